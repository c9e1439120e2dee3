/* version.h — which clpt this is. The number lives in one place, the VERSION file at
 * the repository's root; the Makefile writes it, with the git commit the program is
 * built from, into BUILD/version.c, which only the programs link (so that a new commit
 * relinks them, not every test). */
#ifndef CLPT_VERSION_H
#define CLPT_VERSION_H

/* The semantic version, "MAJOR.MINOR.PATCH" (VERSION). */
extern const char clpt_version_text[];
/* The commit built from, abbreviated, with "-dirty" when the work tree had changes;
 * "unknown" when not built from a git checkout (a release tarball). */
extern const char clpt_commit[];

#endif /* CLPT_VERSION_H */
