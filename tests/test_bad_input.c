/*
 * test_bad_input.c — the bad-input corpus: every file of tests/data/bad/ is loaded with
 * the reader of its extension and must give exactly the documented outcome.
 *
 * A text file says what it expects in comment lines (a binary file, which cannot hold
 * comments, in a NAME.expect file beside it):
 *   # status: input | io | ok
 *   # message: TEXT        the error message must start with TEXT (input, io)
 *   # triangles: N         a mesh that loads must hold N triangles (ok, optional)
 *   # mean: X              the image's mean value (ok, optional)
 * A scene that loads (ok) is also prepared and rendered at its own small size on the
 * scalar device: every pixel must be finite. Run from the project root.
 */
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "util/kmath.h"
#include "io/mesh_load.h"
#include "io/lexer.h"
#include "io/mtl.h"
#include "io/nanovdb.h"
#include "io/obj.h"
#include "io/ply.h"
#include "render_util.h"
#include "scene/scene.h"
#include "io/scene_load.h"
#include "io/texture.h"

#define DIR_BAD "tests/data/bad"

typedef struct {
    char status[16];
    char message[1024];
    long triangles;      /* -1 when not given */
    double mean;         /* NAN when not given */
} Expect;

static int has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n > k && strcmp(s + n - k, suffix) == 0;
}

/* Reads the "# key: value" lines of `path` into e; 0 when a status was found. */
static int read_expect(const char *path, Expect *e)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    char line[1200];
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        if (strncmp(line, "# status: ", 10) == 0) snprintf(e->status, sizeof e->status, "%.15s", line + 10);
        if (strncmp(line, "# message: ", 11) == 0) snprintf(e->message, sizeof e->message, "%.1000s", line + 11);
        if (strncmp(line, "# triangles: ", 13) == 0) e->triangles = strtol(line + 13, NULL, 10);
        if (strncmp(line, "# mean: ", 8) == 0) e->mean = strtod(line + 8, NULL);
    }
    fclose(f);
    return e->status[0] ? 0 : -1;
}

/* Loads `path` with the reader its extension names (a new format adds a line). */
static Status load(const char *path, Scene *s, Error *err)
{
    /* scenes of both formats through the one loader, as clpt reads them */
    if (has_suffix(path, ".scene") || has_suffix(path, ".txt") || has_suffix(path, ".pbrt"))
        return scene_load_file(path, SCENE_FORMAT_AUTO, s, NULL, err);
    uint m, index;
    if (has_suffix(path, ".obj") || has_suffix(path, ".ply")) {
        Status st = scene_add_material(s, "m", material_diffuse(v3(0.5f, 0.5f, 0.5f)), &m, err);
        MeshOptions o = mesh_options(m);
        return st ? st : has_suffix(path, ".obj") ? obj_load(path, s, m, err) : ply_load(path, s, &o, err);
    }
    if (has_suffix(path, ".gltf") || has_suffix(path, ".glb") || has_suffix(path, ".ply.gz") ||
        has_suffix(path, ".obj.gz")) {
        MeshOptions o = mesh_options(NO_INDEX);
        return mesh_load(path, s, &o, err);
    }
    if (has_suffix(path, ".mtl")) {
        MtlLibrary lib;
        memset(&lib, 0, sizeof lib);
        Status st = mtl_load(path, &lib, err);
        mtl_free(&lib);
        return st;
    }
    if (has_suffix(path, ".nvdb") || has_suffix(path, ".nvdb.gz")) {   /* its "density" grid */
        char *data;
        size_t len;
        Status st = lex_read_file(path, &data, &len, err);
        if (st) return st;
        NanoDense d;
        st = nanovdb_read_grid(path, (const unsigned char *)data, len, "density", &d, err);
        free(data);
        if (!st) free(d.density);
        return st;
    }
    static const char *const images[] = { ".png", ".bmp", ".tga", ".hdr", ".psd", ".ppm", ".pgm", ".jpg", ".exr" };
    for (size_t i = 0; i < sizeof images / sizeof images[0]; i++)
        if (has_suffix(path, images[i])) return texture_load_image(s, NULL, path, 0, 0, &index, err);
    return error_set(err, ST_INTERNAL, "no reader for %s: add one to tests/test_bad_input.c", path);
}

/* Renders a scene that loaded: prepare (lights, camera, kd-tree), then the scalar
 * device at the scene's own size, which the corpus keeps small. */
static void check_renders(const char *path, Scene *s, double want_mean)
{
    if (s->image.width * s->image.height > 64 * 64) {
        s->image.width = 8;
        s->image.height = 8;
    }
    if (s->image.spp > 4) s->image.spp = 4;
    Film film;
    Error err = { 0 };
    Status st = render_util_run(s, "scalar", 0, &film, &err);
    CHECK_MSG(st == ST_OK, "%s: render failed: %s", path, err.msg);
    if (st == ST_OK) {
        size_t n = (size_t)film.width * film.height * 3u;
        float *rgb = malloc(n * sizeof *rgb);
        film_resolve(&film, rgb);
        size_t bad = 0;
        for (size_t i = 0; i < n; i++) bad += !isfinite(rgb[i]);
        CHECK_MSG(bad == 0, "%s: %zu of %zu values not finite", path, bad, n);
        free(rgb);
        if (!isnan(want_mean)) CHECK_NEAR(film_mean(&film), want_mean, 1e-6);
    }
    film_free(&film);
    error_clear(&err);
}

static void check_file(const char *path)
{
    Expect e = { "", "", -1, NAN };
    char side[600];
    snprintf(side, sizeof side, "%s.expect", path);
    int found = read_expect(side, &e) == 0 || read_expect(path, &e) == 0;
    CHECK_MSG(found, "%s: no '# status:' line (in the file or in %s)", path, side);
    if (!found) return;
    int ok = strcmp(e.status, "ok") == 0;
    Status want = strcmp(e.status, "io") == 0 ? ST_IO : ST_INPUT;
    CHECK_MSG(ok || strcmp(e.status, "io") == 0 || strcmp(e.status, "input") == 0, "%s: unknown status '%s'",
              path, e.status);

    Scene s;
    Error err = { 0 };
    scene_init(&s);
    Status st = load(path, &s, &err);
    if (ok) {
        CHECK_MSG(st == ST_OK, "%s: expected to load, got status %d: %s", path, st, err.msg);
        if (st == ST_OK && e.triangles >= 0)
            CHECK_MSG((long)s.n_triangles == e.triangles, "%s: %zu triangles, expected %ld", path, s.n_triangles,
                      e.triangles);
        if (st == ST_OK && (has_suffix(path, ".scene") || has_suffix(path, ".txt") || has_suffix(path, ".pbrt")))
            check_renders(path, &s, e.mean);
    } else {
        CHECK_MSG(e.message[0], "%s: an error needs its '# message:' line; this one is:\n    %s", path, err.msg);
        CHECK_MSG(st == want, "%s: status %d, expected %d (%s)", path, st, want, err.msg);
        CHECK_MSG(strncmp(err.msg, e.message, strlen(e.message)) == 0, "\n    got:      %s\n    expected: %s",
                  err.msg, e.message);
    }
    scene_free(&s);
    error_clear(&err);
}

/* One result per file, as if each were a test of its own. */
int main(void)
{
    int count_checked = 0;
    DIR *d = opendir(DIR_BAD);
    if (!d) {
        perror(DIR_BAD);
        return 1;
    }
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.' || has_suffix(e->d_name, ".expect")) continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", DIR_BAD, e->d_name);
        harness_current = path;
        harness_current_failed = 0;
        check_file(path);
        if (harness_current_failed) {
            harness_failed++;
            fprintf(stderr, "FAIL %s\n", path);
        } else {
            harness_passed++;
            fprintf(stderr, "ok   %s\n", path);
        }
        count_checked++;
    }
    closedir(d);
    fprintf(stderr, "%d files checked\n", count_checked);
    if (count_checked < 40) {
        fprintf(stderr, "FAIL only %d files in %s\n", count_checked, DIR_BAD);
        harness_failed++;
    }
    return harness_report();
}
