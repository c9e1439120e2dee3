/* test_cli_habits.c — the command-line habits users bring from other programs (issue
 * 44): the version with its commit, `--` ending the options, bundled short options,
 * "did you mean", the usage hint said once, `-o -` and --stats=json. */
#include <ctype.h>

#include "cli_util.h"
#include "harness.h"

static CliResult r;   /* large: static */

#define ARGS(...) ((const char *const[]){ __VA_ARGS__, NULL })

/* The VERSION file's line, without its newline. */
static void read_version_file(char *buf, size_t size)
{
    buf[0] = '\0';
    FILE *f = fopen("VERSION", "r");
    if (!f) return;
    if (!fgets(buf, (int)size, f)) buf[0] = '\0';
    fclose(f);
    buf[strcspn(buf, "\n")] = '\0';
}

/* "clpt 0.2.0 (commit 0123456789ab)": the one version, and the commit (12 hex digits,
 * maybe -dirty) or "unknown" outside git. */
static void test_version_names_version_and_commit(void)
{
    char version[64], want[96];
    read_version_file(version, sizeof version);
    CHECK_MSG(version[0], "no VERSION file");
    cli_run(ARGS("--version"), &r);
    CHECK_EQ_INT(r.status, 0);
    snprintf(want, sizeof want, "clpt %s (commit ", version);
    CHECK_MSG(strncmp(r.out, want, strlen(want)) == 0, "--version printed '%s'", r.out);
    const char *c = r.out + strlen(want);
    size_t hex = 0;
    while (isxdigit((unsigned char)c[hex])) hex++;
    CHECK_MSG((hex == 12 && (strcmp(c + 12, ")\n") == 0 || strcmp(c + 12, "-dirty)\n") == 0)) ||
                  strcmp(c, "unknown)\n") == 0,
              "--version's commit: '%s'", c);
}

int main(void)
{
    RUN(test_version_names_version_and_commit);
    return harness_report();
}
