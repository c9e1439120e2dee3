/*
 * test_viewer.c — the interactive viewer (docs/viewer.md).
 *
 * The camera moves and the printed camera block (view_camera.c) as units; the command
 * line without a display; and a session as a user has it: under a virtual X display
 * (Xvfb) the viewer shows the Cornell box, xdotool presses C (the start view), W ten
 * times and drags the mouse to the right, presses C and P and Esc. The saved image must
 * show the box nearer (the back wall wider) and turned (its middle further left), and
 * be, bit for bit, the command-line render of the printed camera with as many samples
 * as the viewer says it saved. Every wait has a time limit; the Xvfb started here and
 * the viewer are killed whatever happens. Without Xvfb or xdotool (tools/deps.sh
 * viewer-test) the session is skipped with a message. A second session, with
 * --denoise and Open Image Denoise present, waits for the denoised frame of the last
 * pass, saves (the noisy film: the command line's bits), and turns N off and on again.
 * Without a window (the render thread alone, as the window drives it): quitting while a
 * large frame is being denoised cancels the denoise rather than waiting for it.
 */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <stb_image.h>

#include "cli_util.h"
#include "harness.h"
#include "io/scene_load.h"
#include "render/denoise.h"
#include "render/passes.h"
#include "render/render_scene.h"
#include "viewer/view_camera.h"
#include "viewer/viewer_render.h"

/* ------------------------------------------------------------------ camera units */

static SceneCamera cornell_camera(void)
{
    SceneCamera c;
    memset(&c, 0, sizeof c);
    c.from = (vec3){ 278.0f, 273.0f, -800.0f };
    c.at = (vec3){ 278.0f, 273.0f, 0.0f };
    c.up = (vec3){ 0.0f, 1.0f, 0.0f };
    c.vfov = 39.3077f;
    return c;
}

/* An orthographic camera of clpt's format prints as one, and reads back the same. */
static void test_print_orthographic(void)
{
    SceneCamera c = cornell_camera();
    c.type = CAMERA_ORTHOGRAPHIC;
    c.ortho_width = 555.5f;
    char block[512];
    FILE *f = fmemopen(block, sizeof block, "w");
    CHECK_EQ_INT(view_camera_print(f, &c), 0);
    fclose(f);
    CHECK_STR_CONTAINS(block, "camera { type orthographic  from ");
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    CHECK_EQ_INT(scene_load_bytes("printed.scene", block, strlen(block), SCENE_FORMAT_CLPT, &s, NULL, &err), ST_OK);
    CHECK(s.camera.type == CAMERA_ORTHOGRAPHIC && s.camera.ortho_width == c.ortho_width);
    CHECK_MSG(memcmp(&s.camera.from, &c.from, sizeof c.from) == 0, "from differs after the round trip");
    scene_free(&s);
}

/* The printed block, pasted into a scene, gives back the very floats. */
static void test_print_round_trip(void)
{
    SceneCamera c = cornell_camera();
    view_camera_move(&c, 13.7, -2.1, 55.3);
    CHECK(view_camera_turn(&c, 3.3, -1.7));
    view_camera_zoom(&c, 1.1);
    view_camera_focus(&c, 0.9);
    view_camera_aperture(&c, 1.25, 2.4);
    char block[512];
    FILE *f = fmemopen(block, sizeof block, "w");
    CHECK_EQ_INT(view_camera_print(f, &c), 0);
    fclose(f);
    CHECK_STR_CONTAINS(block, "camera { from ");
    char text[1024];
    snprintf(text, sizeof text, "%ssphere { center 0 0 0 radius 1 material { type diffuse albedo 1 1 1 } }\n", block);
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    CHECK_EQ_INT(scene_load_bytes("printed.scene", text, strlen(text), SCENE_FORMAT_CLPT, &s, NULL, &err), ST_OK);
    CHECK_MSG(memcmp(&s.camera.from, &c.from, sizeof c.from) == 0, "from differs after the round trip");
    CHECK_MSG(memcmp(&s.camera.at, &c.at, sizeof c.at) == 0, "at differs after the round trip");
    CHECK(s.camera.vfov == c.vfov);
    CHECK(s.camera.aperture == c.aperture);
    CHECK(s.camera.focus_dist == c.focus_dist);
    CHECK(c.aperture == 2.4f);
    scene_free(&s);
    error_clear(&err);
}

/* W moves along the view, D to the image's right (-x in the Cornell box, whose +x is on
 * the left), R up; a turn to the right keeps the eye and the target's distance. */
static void test_moves(void)
{
    SceneCamera c = cornell_camera();
    view_camera_move(&c, 0, 0, 10);
    CHECK(c.from.z == -790.0f && c.at.z == 10.0f && c.from.x == 278.0f);
    view_camera_move(&c, 5, 0, 0);
    CHECK(c.from.x == 273.0f && c.at.x == 273.0f);
    view_camera_move(&c, 0, 2, 0);
    CHECK(c.from.y == 275.0f && c.at.y == 275.0f);
    SceneCamera t = c;
    CHECK(view_camera_turn(&t, 90.0, 0.0));
    CHECK(t.from.x == c.from.x && t.from.z == c.from.z);
    CHECK_NEAR(t.at.x, c.from.x - 800.0f, 1e-3);
    CHECK_NEAR(t.at.z, c.from.z, 1e-3);
    /* straight up is refused: the frame would be undefined */
    t = c;
    CHECK(!view_camera_turn(&t, 0.0, 90.0));
    CHECK(memcmp(&t, &c, sizeof t) == 0);
    view_camera_zoom(&c, 100.0);
    CHECK(c.vfov == 170.0f);
    view_camera_aperture(&c, 1.0 / 1.25, 2.0);
    CHECK(c.aperture == 0.0f);
}

/* ------------------------------------------------------------------ without a display */

static void test_no_display(void)
{
    const char *names[] = { "DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER" };
    char *saved[3];
    for (int i = 0; i < 3; i++) {
        const char *v = getenv(names[i]);
        saved[i] = v ? strdup(v) : NULL;
        unsetenv(names[i]);
    }
    CliResult *r = malloc(sizeof *r);
    const char *args[] = { "--interactive", "scenes/cornell-box.scene", NULL };
    cli_run(args, r);
    CHECK_EQ_INT(r->status, 5);
    CHECK_STR_CONTAINS(r->err, "clpt: error: --interactive needs a display for its window, and there is none "
                               "(neither DISPLAY nor WAYLAND_DISPLAY is set)");
    for (int i = 0; i < 3; i++)
        if (saved[i]) {
            setenv(names[i], saved[i], 1);
            free(saved[i]);
        }
    free(r);
}

static void test_usage(void)
{
    CliResult *r = malloc(sizeof *r);
    const char *args[] = { "--interactive", "scenes/cornell-box.scene", "-o", "x.png", NULL };
    cli_run(args, r);
    CHECK_EQ_INT(r->status, 2);
    CHECK_STR_CONTAINS(r->err, "--interactive cannot be combined with --output");
    const char *help[] = { "--help", NULL };
    cli_run(help, r);
    CHECK_STR_CONTAINS(r->out, "  -i, --interactive ");
    free(r);
}

/* ------------------------------------------------------------------ processes */

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int on_path(const char *tool)
{
    const char *path = getenv("PATH");
    char buf[PATH_MAX];
    while (path && *path) {
        const char *colon = strchr(path, ':');
        size_t n = colon ? (size_t)(colon - path) : strlen(path);
        snprintf(buf, sizeof buf, "%.*s/%s", (int)n, path, tool);
        if (access(buf, X_OK) == 0) return 1;
        path = colon ? colon + 1 : NULL;
    }
    return 0;
}

/* Waits up to `seconds` for pid; -1 (and kills it) when it is still running then. */
static int wait_timeout(pid_t pid, double seconds)
{
    double end = now_s() + seconds;
    int ws = 0;
    for (;;) {
        pid_t r = waitpid(pid, &ws, WNOHANG);
        if (r == pid) return WIFEXITED(ws) ? WEXITSTATUS(ws) : 128 + WTERMSIG(ws);
        if (r < 0 || now_s() > end) break;
        usleep(20000);
    }
    kill(pid, SIGKILL);
    waitpid(pid, &ws, 0);
    return -1;
}

/* A video driver that shows no window is no display either: with SDL_VIDEODRIVER=dummy
 * the viewer ran, invisible, and waited for keys nobody could press (so the run is
 * bounded here: a hang fails the check instead of the suite). */
static void test_driver_without_a_window(void)
{
    const char *drivers[] = { "dummy", "offscreen" };
    const char *args[] = { "--interactive", "scenes/cornell-box.scene", NULL };
    const char *old = getenv("SDL_VIDEODRIVER");
    char *saved = old ? strdup(old) : NULL;
    CliResult *r = malloc(sizeof *r);
    for (int i = 0; i < 2; i++) {
        setenv("SDL_VIDEODRIVER", drivers[i], 1);
        CliChild c = cli_start(args);
        int status = wait_timeout(c.pid, 60.0);
        cli_slurp(c.err_fd, r->err);
        close(c.out_fd);
        close(c.err_fd);
        CHECK_MSG(status == 5, "SDL_VIDEODRIVER=%s: status %d (-1: still running after 60 s), stderr: %s",
                  drivers[i], status, r->err);
        char want[400];
        snprintf(want, sizeof want, "clpt: error: --interactive needs a display for its window, and there is none "
                 "(SDL_VIDEODRIVER is '%s', and SDL's '%s' video driver shows no window); render to a file without "
                 "--interactive, or run it where a display is (see docs/viewer.md)\n", drivers[i], drivers[i]);
        CHECK_STR_CONTAINS(r->err, want);
    }
    if (saved) setenv("SDL_VIDEODRIVER", saved, 1);
    else unsetenv("SDL_VIDEODRIVER");
    free(saved);
    free(r);
}

/* Runs a tool (xdotool) to its end, at most 10 s; its stdout into out (may be NULL). */
static int tool_run(const char *const *argv, char *out, size_t out_size)
{
    int fds[2];
    if (pipe(fds) != 0) return -1;
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fds[1], 1);
        int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, 2);
        close(fds[0]);
        execvp(argv[0], (char *const *)argv);
        _exit(127);
    }
    close(fds[1]);
    size_t len = 0;
    double end = now_s() + 10.0;
    struct pollfd p = { fds[0], POLLIN, 0 };
    while (now_s() < end && poll(&p, 1, 100) >= 0) {
        if (!(p.revents & (POLLIN | POLLHUP))) continue;
        char tmp[256];
        ssize_t n = read(fds[0], tmp, sizeof tmp);
        if (n <= 0) break;
        for (ssize_t i = 0; i < n && out && len + 1 < out_size; i++) out[len++] = tmp[i];
    }
    if (out) out[len] = '\0';
    close(fds[0]);
    return wait_timeout(pid, end - now_s() > 0.5 ? end - now_s() : 0.5);
}

/* Xvfb on a display it chooses itself (-displayfd): no clash with a running X server. */
static pid_t xvfb_start(char *display, size_t size)
{
    int fds[2];
    if (pipe(fds) != 0) return -1;
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fds[1], 3);
        int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, 1);
        dup2(devnull, 2);
        execlp("Xvfb", "Xvfb", "-displayfd", "3", "-screen", "0", "640x480x24", "-nolisten", "tcp", (char *)NULL);
        _exit(127);
    }
    close(fds[1]);
    char num[32] = "";
    size_t len = 0;
    double end = now_s() + 20.0;
    struct pollfd p = { fds[0], POLLIN, 0 };
    while (now_s() < end && !memchr(num, '\n', len) && poll(&p, 1, 100) >= 0) {
        if (!(p.revents & (POLLIN | POLLHUP))) continue;
        ssize_t n = read(fds[0], num + len, sizeof num - 1 - len);
        if (n <= 0) break;
        len += (size_t)n;
        num[len] = '\0';
    }
    close(fds[0]);
    if (!memchr(num, '\n', len)) {
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        return -1;
    }
    snprintf(display, size, ":%d", atoi(num));
    return pid;
}

static void xvfb_stop(pid_t pid)
{
    kill(pid, SIGTERM);
    if (wait_timeout(pid, 5.0) < 0) fprintf(stderr, "  Xvfb did not stop on SIGTERM; killed\n");
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *buf = malloc(1 << 20);
    size_t n = buf ? fread(buf, 1, (1 << 20) - 1, f) : 0;
    if (buf) buf[n] = '\0';
    fclose(f);
    return buf;
}

/* How often `text` occurs in the file. */
static int count_in(const char *path, const char *text)
{
    char *s = slurp(path);
    int n = 0;
    for (const char *p = s; p && (p = strstr(p, text)); p += strlen(text)) n++;
    free(s);
    return n;
}

/* Waits until `text` occurs `times` times in the file (the viewer's stdout or stderr). */
static int wait_text(const char *path, const char *text, int times, double seconds)
{
    double end = now_s() + seconds;
    while (now_s() < end) {
        if (count_in(path, text) >= times) return 1;
        usleep(50000);
    }
    fprintf(stderr, "  waited %.0f s for '%s' x%d in %s\n", seconds, text, times, path);
    return 0;
}

/* ------------------------------------------------------------------ the image */

/* The back wall in the middle band of rows: the columns between the red wall (left)
 * and the green wall (right), told apart by their mean colour. */
typedef struct { int left, right; } Wall;

static Wall back_wall(const char *png)
{
    Wall w = { -1, -1 };
    int width, height, ch;
    unsigned char *px = stbi_load(png, &width, &height, &ch, 3);
    if (!px) return w;
    for (int x = 0; x < width; x++) {
        double r = 0, g = 0;
        for (int y = height * 2 / 5; y < height * 3 / 5; y++) {
            r += px[((size_t)y * width + x) * 3];
            g += px[((size_t)y * width + x) * 3 + 1];
        }
        if (x < width / 2 && r > 1.8 * g + 1.0) w.left = x + 1;
        if (x >= width / 2 && w.right < 0 && g > 1.3 * r + 1.0) w.right = x;
    }
    stbi_image_free(px);
    return w;
}

/* The saved names and spp from "clpt: saved A.png and A.pfm (N spp)", the k-th save. */
static int parse_save(const char *err_path, int k, char *png, char *pfm, unsigned *spp)
{
    char *s = slurp(err_path);
    const char *p = s;
    for (int i = 0; p && i <= k; i++) {
        p = strstr(p, "clpt: saved ");
        if (p && i < k) p += 12;
    }
    int ok = p && sscanf(p, "clpt: saved %255s and %255s (%u spp", png, pfm, spp) == 3;
    free(s);
    return ok;
}

/* The Cornell box with its camera line replaced by `camera` (the printed block). */
static int write_scene_with_camera(const char *path, const char *camera)
{
    char *s = slurp("scenes/cornell-box.scene");
    if (!s) return 0;
    char *line = strstr(s, "\ncamera {");
    char *end = line ? strchr(line + 1, '\n') : NULL;
    FILE *f = fopen(path, "w");
    if (!line || !end || !f) {
        free(s);
        if (f) fclose(f);
        return 0;
    }
    fprintf(f, "%.*s\n%s%s", (int)(line - s), s, camera, end + 1);
    fclose(f);
    free(s);
    return 1;
}

typedef struct {
    char dir[64], out[128], err[128], display[32];
    pid_t xvfb, viewer;
    char window[64];
    const char *extra;            /* one more flag for the viewer, or NULL */
} Session;

static int xdo(const char *a, const char *b, const char *c, const char *d, const char *e)
{
    const char *argv[] = { "xdotool", a, b, c, d, e, NULL };
    return tool_run(argv, NULL, 0);
}

/* The viewer, started in its own folder (its saves go to the current folder). */
static int session_start(Session *s)
{
    char prog[PATH_MAX], scene[PATH_MAX];
    if (!realpath(CLI_PROGRAM, prog) || !realpath("scenes/cornell-box.scene", scene)) return 0;
    snprintf(s->out, sizeof s->out, "%s/out.txt", s->dir);
    snprintf(s->err, sizeof s->err, "%s/err.txt", s->dir);
    s->viewer = fork();
    if (s->viewer == 0) {
        if (chdir(s->dir) != 0) _exit(126);
        int o = open("out.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644), e = open("err.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(o, 1);
        dup2(e, 2);
        setenv("DISPLAY", s->display, 1);
        execl(prog, prog, "--interactive", scene, "--width", "128", "--height", "128", "--spp", "4", "--seed", "5",
              s->extra, (char *)NULL);
        _exit(127);
    }
    if (!wait_text(s->err, "clpt: viewer: ", 1, 120.0)) return 0;
    char out[256] = "";
    const char *search[] = { "xdotool", "search", "--sync", "--name", "^clpt", NULL };
    if (tool_run(search, out, sizeof out) != 0 || sscanf(out, "%63s", s->window) != 1) return 0;
    /* keys go to the window under the pointer (Xvfb runs no window manager) */
    return xdo("mousemove", "--window", s->window, "64", "64") == 0;
}

static void session_user(Session *s)
{
    CHECK(xdo("key", "c", NULL, NULL, NULL) == 0);
    CHECK(wait_text(s->err, "clpt: saved ", 1, 60.0));
    const char *w[] = { "xdotool", "key", "--delay", "20", "w", "w", "w", "w", "w", "w", "w", "w", "w", "w", NULL };
    CHECK(tool_run(w, NULL, 0) == 0);
    const char *drag[] = { "xdotool", "mousedown", "1", "mousemove_relative", "--", "12", "0", "mouseup", "1", NULL };
    CHECK(tool_run(drag, NULL, 0) == 0);
    usleep(300000);
    CHECK(xdo("key", "c", NULL, NULL, NULL) == 0);
    CHECK(wait_text(s->err, "clpt: saved ", 2, 60.0));
    CHECK(xdo("key", "p", NULL, NULL, NULL) == 0);
    CHECK(wait_text(s->out, "camera {", 1, 20.0));
    CHECK(xdo("key", "Escape", NULL, NULL, NULL) == 0);
    int status = wait_timeout(s->viewer, 30.0);
    s->viewer = 0;
    CHECK_EQ_INT(status, 0);
}

/* The second save against the first (the start view) and against the command line. */
static void session_check(Session *s)
{
    char png0[256], pfm0[256], png1[256], pfm1[256], path[512], ref[512], cmd_scene[512];
    unsigned spp0 = 0, spp1 = 0;
    CHECK(parse_save(s->err, 0, png0, pfm0, &spp0));
    CHECK(parse_save(s->err, 1, png1, pfm1, &spp1));
    CHECK(spp1 >= 1 && spp1 <= 4);
    CHECK(strcmp(png0, png1) != 0);   /* a save never overwrites an earlier one */
    snprintf(path, sizeof path, "%s/%s", s->dir, png0);
    Wall a = back_wall(path);
    snprintf(path, sizeof path, "%s/%s", s->dir, png1);
    Wall b = back_wall(path);
    CHECK_MSG(a.left > 0 && a.right > a.left && b.left > 0 && b.right > b.left, "walls %d..%d, %d..%d", a.left,
              a.right, b.left, b.right);
    /* nearer after W: the back wall is wider; turned right by the drag: it moved left */
    CHECK_MSG(b.right - b.left > a.right - a.left + 4, "back wall %d px wide, %d px before W",
              b.right - b.left, a.right - a.left);
    CHECK_MSG(b.left + b.right < a.left + a.right - 4, "back wall's middle at %d, %d before the drag",
              (b.left + b.right) / 2, (a.left + a.right) / 2);

    char *out = slurp(s->out);
    char *cam = out ? strstr(out, "camera {") : NULL;
    char *nl = cam ? strchr(cam, '\n') : NULL;
    CHECK(cam && nl);
    if (!cam || !nl) {
        free(out);
        return;
    }
    nl[1] = '\0';
    snprintf(cmd_scene, sizeof cmd_scene, "%s/printed.scene", s->dir);
    CHECK(write_scene_with_camera(cmd_scene, cam));
    free(out);
    char spp[16];
    snprintf(spp, sizeof spp, "%u", spp1);
    const char *exts[] = { "pfm", "png" };
    for (int i = 0; i < 2; i++) {
        snprintf(ref, sizeof ref, "%s/cli.%s", s->dir, exts[i]);
        const char *args[] = { cmd_scene, "--width", "128", "--height", "128", "--spp", spp, "--seed", "5",
                               "-q", "-o", ref, NULL };
        CliResult *r = malloc(sizeof *r);
        cli_run(args, r);
        CHECK_EQ_INT(r->status, 0);
        free(r);
        snprintf(path, sizeof path, "%s/%s", s->dir, i == 0 ? pfm1 : png1);
        CHECK_MSG(files_equal(path, ref), "%s differs from the command line's %s", path, ref);
    }
}

/* Xvfb and the viewer in it, session_user's part done by `user`, then the check's. */
static void session_run(const char *extra, void (*user)(Session *), void (*check)(Session *))
{
    Session s;
    memset(&s, 0, sizeof s);
    s.extra = extra;
    snprintf(s.dir, sizeof s.dir, "/tmp/clpt-test-viewer-XXXXXX");
    CHECK(mkdtemp(s.dir) != NULL);
    s.xvfb = xvfb_start(s.display, sizeof s.display);
    CHECK_MSG(s.xvfb > 0, "Xvfb did not start");
    if (s.xvfb <= 0) return;
    setenv("DISPLAY", s.display, 1);   /* for xdotool */
    int started = session_start(&s);
    CHECK_MSG(started, "the viewer did not open its window");
    if (started) user(&s);
    if (s.viewer > 0) {
        kill(s.viewer, SIGKILL);
        waitpid(s.viewer, NULL, 0);
        char *log = slurp(s.err);
        fprintf(stderr, "  the viewer was killed; its stderr:\n%s\n", log ? log : "");
        free(log);
    }
    xvfb_stop(s.xvfb);
    unsetenv("DISPLAY");
    if (started) check(&s);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", s.dir);
    if (system(cmd) != 0) fprintf(stderr, "  could not remove %s\n", s.dir);
}

/* --denoise starts with the denoised view on: the last pass (4 spp) is shown denoised;
 * C saves the film as rendered; N off shows the noisy frame, N on the denoised one again
 * (denoised once: the film has not changed). */
static void denoise_user(Session *s)
{
    CHECK(wait_text(s->err, "clpt: viewer: showing the 4-spp frame denoised", 1, 120.0));
    CHECK(xdo("key", "c", NULL, NULL, NULL) == 0);
    CHECK(wait_text(s->err, "clpt: saved ", 1, 60.0));
    CHECK(xdo("key", "n", NULL, NULL, NULL) == 0);
    CHECK(wait_text(s->err, "clpt: viewer: denoised view off", 1, 20.0));
    CHECK(xdo("key", "n", NULL, NULL, NULL) == 0);
    CHECK(wait_text(s->err, "clpt: viewer: showing the 4-spp frame denoised", 2, 20.0));
    CHECK(xdo("key", "Escape", NULL, NULL, NULL) == 0);
    int status = wait_timeout(s->viewer, 30.0);
    s->viewer = 0;
    CHECK_EQ_INT(status, 0);
}

static void denoise_check(Session *s)
{
    char png[256], pfm[256], path[512], ref[512];
    unsigned spp = 0;
    CHECK(parse_save(s->err, 0, png, pfm, &spp));
    CHECK_EQ_INT(spp, 4);
    CHECK_EQ_INT(count_in(s->err, "clpt: viewer: showing the 4-spp frame denoised"), 2);
    snprintf(ref, sizeof ref, "%s/cli.pfm", s->dir);
    const char *args[] = { "scenes/cornell-box.scene", "--width", "128", "--height", "128", "--spp", "4", "--seed",
                           "5", "-q", "-o", ref, NULL };
    CliResult *r = malloc(sizeof *r);
    cli_run(args, r);
    CHECK_EQ_INT(r->status, 0);
    free(r);
    snprintf(path, sizeof path, "%s/%s", s->dir, pfm);
    CHECK_MSG(files_equal(path, ref), "the save with the denoised view on is not the film as rendered");
}

static void test_session_denoise(void)
{
    Denoiser *d = NULL;
    Error err = { 0 };
    if (!on_path("Xvfb") || !on_path("xdotool") || denoiser_open(&d, &err) != ST_OK) {
        fprintf(stderr, "  Xvfb, xdotool or Open Image Denoise missing: the denoised session is skipped (%s)\n",
                err.msg);
        error_clear(&err);
        return;
    }
    denoiser_close(d);
    session_run("--denoise", denoise_user, denoise_check);
}

static void test_session(void)
{
    if (!on_path("Xvfb") || !on_path("xdotool")) {
        fprintf(stderr, "  Xvfb or xdotool not installed (sh tools/deps.sh viewer-test): the viewer session is "
                        "skipped\n");
        return;
    }
    session_run(NULL, session_user, session_check);
}


/* ------------------------------------------------------------------ cancelling a denoise */

/* What the two denoised-view tests below share: Open Image Denoise, the Cornell box at
 * size x size and spp prepared, the scalar device. f->st is the set-up's status;
 * f->opened is 0 where OIDN is missing (the test is skipped, saying so). */
typedef struct {
    Denoiser *d;
    Error err;
    Scene s;
    RenderScene rs;
    Device **devs;
    size_t n_devs;
    DeviceConfig dc;
    int prepared, opened;
    Status st;
} DenoiseViewFixture;

static void denoise_view_open(DenoiseViewFixture *f, int size, int spp)
{
    memset(f, 0, sizeof *f);
    if (denoiser_open(&f->d, &f->err) != ST_OK) {
        fprintf(stderr, "  Open Image Denoise missing: skipped (%s)\n", f->err.msg);
        error_clear(&f->err);
        return;
    }
    f->opened = 1;
    scene_init(&f->s);
    f->st = scene_load_file("scenes/cornell-box.scene", SCENE_FORMAT_AUTO, &f->s, NULL, &f->err);
    if (f->st == ST_OK) {
        f->s.image.width = f->s.image.height = size;
        f->s.image.spp = spp;
        f->st = render_scene_prepare(&f->s, 0, &f->rs, &f->err);
        f->prepared = f->st == ST_OK;
    }
    if (f->st == ST_OK)
        f->st = device_open_all("scalar", &f->dc, &f->rs.ds, NULL, NULL, &f->devs, &f->n_devs, &f->err);
    CHECK_MSG(f->st == ST_OK, "setting up: %s", f->err.msg);
}

/* The test's last status checked, then everything denoise_view_open made freed. */
static void denoise_view_close(DenoiseViewFixture *f, Status st)
{
    CHECK_MSG(st == ST_OK, "%s", f->err.msg);
    for (size_t i = 0; i < f->n_devs; i++) device_close(f->devs[i]);
    free(f->devs);
    if (f->prepared) render_scene_free(&f->rs);
    scene_free(&f->s);
    error_clear(&f->err);
    denoiser_close(f->d);
}


/* The render thread (viewer_render.h) on the scalar device, the Cornell box at 640 x
 * 640 with a cap of 1 spp and the denoised view on: its one pass is followed by a
 * denoise of seconds on a CPU (features, their prefilter, the colour). Quitting during it
 * (viewer_render_stop, what Esc does) must cancel it: no frame counted as denoised, one
 * cancelled. Not a timing test: the counters say whether OIDN was stopped or ran to the
 * end; the seconds are printed. Where the denoise ends before it can be stopped (OIDN on
 * a GPU takes milliseconds), there is nothing to cancel and the test says so. */
static void test_quit_cancels_denoise(void)
{
    DenoiseViewFixture f;
    denoise_view_open(&f, 640, 1);
    if (!f.opened) return;
    Status st = f.st;
    ViewerRender *vr = calloc(1, sizeof *vr);
    if (st == ST_OK && vr &&
        (st = viewer_render_start(vr, f.devs, f.n_devs, &f.rs.ds, &f.dc, &f.s.camera, 1, 0, f.d, &f.err)) == ST_OK) {
        /* the features are rendered and prefiltered; the colour's filter, the longest
         * part, begins */
        int in_denoise = 0;
        for (double t0 = now_s(); now_s() - t0 < 300.0;) {
            pthread_mutex_lock(&vr->lock);
            in_denoise = vr->denoising == 2 || vr->denoise_count;
            pthread_mutex_unlock(&vr->lock);
            if (in_denoise) break;
            usleep(2000);
        }
        CHECK_MSG(in_denoise, "the 1-spp frame was not denoised within 300 s");
        usleep(200000);   /* into OIDN's filter */
        pthread_mutex_lock(&vr->lock);
        int ended = vr->denoise_count != 0;
        pthread_mutex_unlock(&vr->lock);
        double t0 = now_s();
        st = viewer_render_stop(vr, &f.err);
        double waited = now_s() - t0;
        CHECK_MSG(st == ST_OK, "rendering failed: %s", f.err.msg);
        if (ended) {
            fprintf(stderr, "  the denoise ended before the stop (%s device): nothing to cancel\n",
                    denoiser_device_kind(f.d));
        } else {
            CHECK_EQ_INT((int)vr->denoise_count, 0);
            CHECK_EQ_INT((int)vr->denoise_cancels, 1);
            printf("     (quitting during a 640x640 denoise took %.3f s)\n", waited);
        }
    }
    free(vr);
    denoise_view_close(&f, st);
}

/* The denoised view keeps the lamp as --denoise does: its directly seen emission is left
 * out of the denoiser and added back (docs/viewer.md, "The denoised view"), so the
 * pixels the lamp covers whole keep its radiance in the denoised 4-spp frame (within
 * 0.03 of the lamp's 17 here); given to OIDN they moved by up to 2.6. */
static void test_denoised_view_keeps_the_lamp(void)
{
    DenoiseViewFixture f;
    denoise_view_open(&f, 64, 4);
    if (!f.opened) return;
    Status st = f.st;
    ViewerRender *vr = calloc(1, sizeof *vr);
    static int64_t acc[2][64 * 64 * 3];
    if (st == ST_OK && vr &&
        (st = viewer_render_start(vr, f.devs, f.n_devs, &f.rs.ds, &f.dc, &f.s.camera, 4, 0, f.d, &f.err)) == ST_OK) {
        int done = 0;
        for (double t0 = now_s(); now_s() - t0 < 300.0 && !done;) {
            usleep(2000);
            pthread_mutex_lock(&vr->lock);
            done = vr->denoised_samples == 4 && vr->samples == 4;
            if (done) {
                size_t lamp = 0;
                float worst = 0.0f;
                for (size_t i = 0; i < (size_t)64 * 64; i++) {
                    if (!(vr->rgb[3 * i] > 16.99f)) continue;   /* covered whole by the lamp */
                    lamp++;
                    for (int c = 0; c < 3; c++) {
                        float diff = fabsf(vr->denoised[3 * i + c] - vr->rgb[3 * i + c]);
                        if (diff > worst) worst = diff;
                    }
                }
                CHECK_MSG(lamp >= 4, "%zu lamp pixels", lamp);
                CHECK_MSG(worst < 0.1f, "the lamp's pixels moved by %g in the denoised view", worst);
                printf("     (%zu lamp pixels, denoised within %.2g of the lamp)\n", lamp, worst);
                /* the emission accumulated along the passes 1, 2, 4 */
                for (int k = 0; k < 2; k++) {
                    CHECK_EQ_INT((long long)vr->emission[k].samples, k ? 16 : 4);
                    if (vr->emission[k].sum) memcpy(acc[k], vr->emission[k].sum, sizeof acc[k]);
                }
            }
            pthread_mutex_unlock(&vr->lock);
        }
        CHECK_MSG(done, "the 4-spp frame was not denoised within 300 s");
        st = viewer_render_stop(vr, &f.err);
        /* ... is the emission of those samples rendered at once, to the bit */
        ScheduleConfig cfg;
        memset(&cfg, 0, sizeof cfg);
        PassContext pc = { f.devs, f.n_devs, &f.rs, &cfg, NULL, NULL, NULL };
        for (int k = 0; k < 2 && st == ST_OK; k++) {
            Film once;
            double secs = 0.0;
            st = passes_data_film(&pc, INTEGRATOR_FEATURE_EMISSION, k ? 16 : 4, 0, 0, &once, &secs, &f.err);
            CHECK_MSG(st == ST_OK && memcmp(once.sum, acc[k], sizeof acc[k]) == 0,
                      "the emission accumulated along the passes differs from one render (%d)", k);
            film_free(&once);
        }
    }
    free(vr);
    denoise_view_close(&f, st);
}

int main(void)
{
    RUN(test_print_round_trip);
    RUN(test_print_orthographic);
    RUN(test_moves);
    RUN(test_no_display);
    RUN(test_driver_without_a_window);
    RUN(test_usage);
    RUN(test_session);
    RUN(test_session_denoise);
    RUN(test_quit_cancels_denoise);
    RUN(test_denoised_view_keeps_the_lamp);
    return harness_report();
}
