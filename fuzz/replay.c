/*
 * replay.c — the regression test of one fuzz target (see fuzz.h): linked with
 * fuzz/fuzz_NAME.c, it feeds the target every file of tests/data/fuzz/NAME/ and every
 * seed file (tests/data/ and scenes/, by the target's FUZZ_SEEDS extensions). A file
 * passes when the target returns: a crash, a sanitizer report (make test-asan) or an
 * abort from a FUZZ_ASSERT ends the program, which tests/run.sh counts as a failure.
 * Run from the project root.
 */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "fuzz.h"
#include "harness.h"

#ifndef FUZZ_NAME
#error "FUZZ_NAME must name the target (the Makefile defines it)"
#endif

static int has_seed_extension(const char *name)
{
    const char *dot = strrchr(name, '.');
    if (!dot || dot == name) return 0;
    size_t n = strlen(dot + 1);
    for (const char *e = fuzz_seed_extensions; *e;) {
        while (*e == ' ') e++;
        size_t k = strcspn(e, " ");
        if (k && k == n && strncmp(e, dot + 1, n) == 0) return 1;
        e += k;
    }
    return 0;
}

static int replay_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    size_t cap = 4096, n = 0;
    unsigned char *data = malloc(cap);
    size_t got;
    while (data && (got = fread(data + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            unsigned char *grown = realloc(data, cap * 2);
            if (!grown) {
                free(data);
                data = NULL;
                break;
            }
            data = grown;
            cap *= 2;
        }
    }
    fclose(f);
    if (!data) return -1;
    LLVMFuzzerTestOneInput(data, n);
    free(data);
    return 0;
}

/* Replays the files of `dir` (recursively): all of them, or only seeds. */
static void replay_dir(const char *dir, int seeds_only, int *count)
{
    DIR *d = opendir(dir);
    if (!d) return;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat sb;
        if (stat(path, &sb) != 0) continue;
        if (S_ISDIR(sb.st_mode)) {
            /* another target's regression files are not this target's seeds */
            if (seeds_only && strcmp(path, "tests/data/fuzz") == 0) continue;
            replay_dir(path, seeds_only, count);
            continue;
        }
        if (!S_ISREG(sb.st_mode) || (seeds_only && !has_seed_extension(e->d_name))) continue;
        harness_current = path;
        harness_current_failed = 0;
        CHECK_MSG(replay_file(path) == 0, "cannot read %s", path);
        if (harness_current_failed) {
            harness_failed++;
            fprintf(stderr, "FAIL %s\n", path);
        } else {
            harness_passed++;
            fprintf(stderr, "ok   %s\n", path);
        }
        (*count)++;
    }
    closedir(d);
}

int main(void)
{
    int regressions = 0, seeds = 0;
    replay_dir("tests/data/fuzz/" FUZZ_NAME, 0, &regressions);
    replay_dir("tests/data", 1, &seeds);
    replay_dir("scenes", 1, &seeds);
    fprintf(stderr, "fuzz target %s: %d regression files, %d seed files replayed\n", FUZZ_NAME,
            regressions, seeds);
    if (seeds == 0) {
        fprintf(stderr, "FAIL no seed file has an extension of FUZZ_SEEDS(\"%s\")\n",
                fuzz_seed_extensions);
        harness_failed++;
    }
    return harness_report();
}
