/* test_install.c — `make install` as a packager runs it (PREFIX, DESTDIR), then the
 * installed program as a user meets it: it renders from another folder (nothing read
 * from the source tree), finds the Open Image Denoise installed beside it, its man page
 * renders without a warning, and the bash and zsh completions load and complete a flag.
 * The files come from BUILD (the Makefile's build folder), which `make test` has built:
 * the sub-make only copies (INSTALL_NO_BUILD=1, so that under test-asan it does not
 * rebuild the folder with the plain flags). */
#include "cli_util.h"
#include "harness.h"

static char stage[64];     /* DESTDIR */
static CliResult r_version; /* large: static */
static char cmd[4096];

/* Runs a shell command line; its exit status (-1 if it could not run). */
static int sh(const char *line)
{
    int st = system(line);
    return st == -1 || !WIFEXITED(st) ? -1 : WEXITSTATUS(st);
}

/* The whole of a (small) file as text; "" if it cannot be read. */
static const char *slurp(const char *path)
{
    static char buf[CLI_OUT_MAX];
    buf[0] = '\0';
    FILE *f = fopen(path, "rb");
    if (!f) return buf;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static int installed(const char *rel)
{
    char path[256];
    snprintf(path, sizeof path, "%s/usr/%s", stage, rel);
    return file_exists(path);
}

/* make install into the stage; the make variables of the calling make (jobserver
 * descriptors this process does not hold) are left out. */
static int install_ok;
static void test_make_install_places_every_file(void)
{
    snprintf(cmd, sizeof cmd,
             "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s --no-print-directory BUILD=%s INSTALL_NO_BUILD=1 "
             "PREFIX=/usr DESTDIR=%s install > %s/make.log 2>&1", CLPT_BUILD_DIR, stage, stage);
    int st = sh(cmd);
    snprintf(cmd, sizeof cmd, "%s/make.log", stage);
    CHECK_MSG(st == 0, "make install: exit %d: %s", st, slurp(cmd));
    const char *files[] = { "bin/clpt", "share/man/man1/clpt.1", "share/bash-completion/completions/clpt",
                            "share/zsh/site-functions/_clpt" };
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) CHECK_MSG(installed(files[i]), "no %s", files[i]);
    /* the C API and its clpt.pc come with the public header, when it exists */
    int api = file_exists("include/clpt/clpt.h");
    CHECK_EQ_INT(installed("include/clpt/clpt.h"), api);
    CHECK_EQ_INT(installed("lib/pkgconfig/clpt.pc"), api);
    install_ok = st == 0 && installed("bin/clpt");
}

/* The installed program, run from the stage with a copy of a scene: the same version,
 * and an image. */
static void test_installed_clpt_renders(void)
{
    if (!install_ok) return;
    cli_run((const char *const[]){ "--version", NULL }, &r_version);
    snprintf(cmd, sizeof cmd, "cp scenes/cornell-box.scene %s/box.scene && cd %s && ./usr/bin/clpt --version > version.txt "
             "&& ./usr/bin/clpt box.scene --device scalar --width 16 --height 12 --spp 2 -q -o out.png 2> render.log",
             stage, stage);
    int st = sh(cmd);
    char path[256];
    snprintf(path, sizeof path, "%s/render.log", stage);
    CHECK_MSG(st == 0, "installed clpt: exit %d: %s", st, slurp(path));
    snprintf(path, sizeof path, "%s/version.txt", stage);
    CHECK_MSG(strcmp(slurp(path), r_version.out) == 0, "installed --version '%s', built '%s'", slurp(path), r_version.out);
    snprintf(path, sizeof path, "%s/out.png", stage);
    CHECK(file_exists(path));
}

/* With Open Image Denoise fetched into BUILD/oidn, make install copies it to
 * PREFIX/lib/clpt/oidn (BINDIR/../lib/clpt/oidn), and the installed clpt's --denoise
 * loads it from there: from the stage, not from the build folder or the system. */
static void test_installed_clpt_finds_oidn(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/oidn/lib/libOpenImageDenoise.so.2", CLPT_BUILD_DIR);
    if (!install_ok) return;
    if (!file_exists(path)) {
        printf("     (skipped: no Open Image Denoise in %s/oidn; sh tools/deps.sh oidn fetches it)\n", CLPT_BUILD_DIR);
        return;
    }
    CHECK(installed("lib/clpt/oidn/lib/libOpenImageDenoise.so.2"));
    CHECK(installed("lib/clpt/oidn/SOURCE"));
    snprintf(cmd, sizeof cmd, "cd %s && env -u CLPT_OIDN_DIR ./usr/bin/clpt box.scene --device scalar --width 16 "
             "--height 12 --spp 2 --denoise -o denoised.png 2> denoise.log", stage);
    int st = sh(cmd);
    snprintf(path, sizeof path, "%s/denoise.log", stage);
    const char *log = slurp(path);
    CHECK_MSG(st == 0, "installed clpt --denoise: exit %d: %s", st, log);
    char want[256];
    snprintf(want, sizeof want, "%s/usr/lib/clpt/oidn/lib/libOpenImageDenoise.so.2", stage);
    CHECK_STR_CONTAINS(log, want);
}

/* A user's program built with pkg-config against an installed library: installed with
 * PREFIX the stage itself (so clpt.pc names where the files are), examples/render.c
 * compiled with `pkg-config --cflags --libs clpt` alone, run against the installed
 * libclpt.so, and its image the program's bits. */
static void test_pkg_config_builds_the_example(void)
{
    if (!install_ok || !file_exists("include/clpt/clpt.h")) return;
    /* a sanitizer build's library needs the sanitizer runtime in the program, which a
     * plain `cc` link has not (test_api builds and runs against it there) */
    if (getenv("ASAN_OPTIONS")) {
        printf("     (skipped under the sanitizers: a plain cc link lacks their runtime)\n");
        return;
    }
    char prefix[128];
    snprintf(prefix, sizeof prefix, "%s/prefix", stage);
    snprintf(cmd, sizeof cmd,
             "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s --no-print-directory BUILD=%s INSTALL_NO_BUILD=1 "
             "PREFIX=%s install > %s/make-prefix.log 2>&1 && PKG_CONFIG_PATH=%s/lib/pkgconfig cc -std=c11 -o %s/example "
             "examples/render.c $(PKG_CONFIG_PATH=%s/lib/pkgconfig pkg-config --cflags --libs clpt) "
             "-Wl,-rpath,%s/lib > %s/cc.log 2>&1",
             CLPT_BUILD_DIR, prefix, stage, prefix, stage, prefix, prefix, stage);
    int st = sh(cmd);
    char path[256];
    snprintf(path, sizeof path, "%s/cc.log", stage);
    CHECK_MSG(st == 0, "install with PREFIX and build the example with pkg-config: exit %d: %s", st, slurp(path));
    if (st) return;
    snprintf(cmd, sizeof cmd,
             "%s/example scenes/cornell-box.scene %s/api.pfm --device=scalar --width=16 --height=12 --spp=2 "
             "2> %s/example.log && %s/clpt scenes/cornell-box.scene --device scalar --width 16 --height 12 --spp 2 "
             "-q -o %s/cli.pfm && cmp -s %s/api.pfm %s/cli.pfm && ldd %s/example | grep -q '%s/lib/libclpt.so'",
             stage, stage, stage, CLPT_BUILD_DIR, stage, stage, stage, stage, prefix);
    st = sh(cmd);
    snprintf(path, sizeof path, "%s/example.log", stage);
    CHECK_MSG(st == 0, "the example built with pkg-config, against the installed library: exit %d: %s", st,
              slurp(path));
}

/* man renders the installed page without a warning (groff's, through man-db). */
static void test_man_page_renders_without_warnings(void)
{
    if (!install_ok) return;
    snprintf(cmd, sizeof cmd, "MANWIDTH=80 man --warnings -l %s/usr/share/man/man1/clpt.1 > %s/man.txt 2> %s/man.err",
             stage, stage, stage);
    int st = sh(cmd);
    char path[256];
    snprintf(path, sizeof path, "%s/man.err", stage);
    CHECK_MSG(st == 0 && slurp(path)[0] == '\0', "man: exit %d: %s", st, slurp(path));
    snprintf(path, sizeof path, "%s/man.txt", stage);
    const char *page = slurp(path);
    CHECK_STR_CONTAINS(page, "clpt - a portable OpenCL path tracer");
    CHECK_STR_CONTAINS(page, "--stats[=text|json]");
    CHECK_STR_CONTAINS(page, "EXIT STATUS");
}

/* The bash completion, sourced as bash-completion would, asked as the shell asks
 * (COMP_WORDS, COMP_CWORD): flags, a choice's words, a switch's words after '=',
 * image files for -o, scene files for the scene, the device groups. */
static void test_bash_completion(void)
{
    if (!install_ok) return;
    snprintf(cmd, sizeof cmd,
             "cd %s && touch a.exr b.txt && PATH=$PWD/usr/bin:$PATH bash --norc -c '"
             "source usr/share/bash-completion/completions/clpt; "
             "complete -p clpt; "
             "c() { COMP_WORDS=(\"$@\"); COMP_CWORD=$(($# - 1)); COMPREPLY=(); _clpt; "
             "printf \"[%%s]\" \"${COMPREPLY[@]}\"; echo; }; "
             "c clpt --sp; c clpt --sampler \"\"; c clpt --stats = \"\"; c clpt -qo \"\" ; c clpt -o \"\"; c clpt \"\"; "
             "c clpt --device \"\"' > bash.txt 2>&1", stage);
    int st = sh(cmd);
    char path[256];
    snprintf(path, sizeof path, "%s/bash.txt", stage);
    const char *got = slurp(path);
    CHECK_MSG(st == 0, "bash: exit %d: %s", st, got);
    /* one line per question; file names come in the folder's order */
    static const struct { int line; const char *has, *lacks; } want[] = {
        { 0, "complete -F _clpt clpt", NULL }, { 1, "[--spp]", "[--seed]" }, { 1, "[--split]", NULL },
        { 2, "[sobol][independent]", NULL }, { 3, "[text][json]", NULL }, { 4, "[a.exr]", "[b.txt]" },
        { 4, "[out.png]", "[box.scene]" }, { 5, "[a.exr]", "[box.scene]" }, { 6, "[box.scene]", "[out.png]" },
        { 6, "[b.txt]", "[a.exr]" }, { 7, "[all][gpu][cpu][scalar]", NULL },
    };
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        char line[1024] = "";
        const char *p = got;
        for (int k = 0; k < want[i].line && p; k++) p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL;
        if (p) snprintf(line, sizeof line, "%.*s", (int)strcspn(p, "\n"), p);
        CHECK_MSG(strstr(line, want[i].has) && !(want[i].lacks && strstr(line, want[i].lacks)),
                  "bash completion, line %d: '%s' wanted%s%s: '%s'", want[i].line, want[i].has,
                  want[i].lacks ? ", without " : "", want[i].lacks ? want[i].lacks : "", line);
    }
}

/* The zsh completion in an interactive zsh on a pseudo-terminal
 * (tests/data/completion.zsh). Skipped, saying so, only where zsh is not installed. */
static void test_zsh_completion(void)
{
    if (!install_ok) return;
    if (sh("command -v zsh > /dev/null 2>&1") != 0) {
        printf("SKIP zsh completion: zsh is not installed (sh tools/deps.sh install-test installs it)\n");
        return;
    }
    snprintf(cmd, sizeof cmd, "timeout 60 zsh -f tests/data/completion.zsh %s/usr/share/zsh/site-functions > %s/zsh.txt 2>&1",
             stage, stage);
    int st = sh(cmd);
    char path[256];
    snprintf(path, sizeof path, "%s/zsh.txt", stage);
    const char *got = slurp(path);
    CHECK_MSG(st == 0, "zsh: exit %d (124: no completion came): %s", st, got);
    CHECK_STR_CONTAINS(got, "--spp");
    CHECK_STR_CONTAINS(got, "samples per pixel");   /* its description: the list came from _clpt */
    CHECK_STR_CONTAINS(got, "RESULT: clpt --interactive");
}

/* make uninstall takes every file back out. */
static void test_make_uninstall(void)
{
    if (!install_ok) return;
    snprintf(cmd, sizeof cmd,
             "env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s --no-print-directory BUILD=%s PREFIX=/usr DESTDIR=%s "
             "uninstall > /dev/null 2>&1 && test -z \"$(find %s/usr ! -type d)\"", CLPT_BUILD_DIR, stage, stage);
    CHECK_MSG(sh(cmd) == 0, "files left after make uninstall in %s/usr", stage);
}

int main(void)
{
    snprintf(stage, sizeof stage, "/tmp/clpt-test-install-XXXXXX");
    if (!mkdtemp(stage)) {
        perror("mkdtemp");
        return 1;
    }
    RUN(test_make_install_places_every_file);
    RUN(test_installed_clpt_renders);
    RUN(test_installed_clpt_finds_oidn);
    RUN(test_pkg_config_builds_the_example);
    RUN(test_man_page_renders_without_warnings);
    RUN(test_bash_completion);
    RUN(test_zsh_completion);
    RUN(test_make_uninstall);
    snprintf(cmd, sizeof cmd, "rm -rf %s", stage);
    sh(cmd);
    return harness_report();
}
