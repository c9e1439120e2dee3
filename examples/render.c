/*
 * render.c — clpt's C API (include/clpt/clpt.h) in one program: reads a scene, takes
 * render settings as the command line names them, renders with a progress line and
 * writes the image as a PFM file (linear floats, the same bits as `clpt -o OUT.pfm`).
 *
 *   render SCENE OUT.pfm [--device=SPEC] [--set=KEY=VALUE] [--NAME=VALUE ...]
 *   render scenes/cornell-box.scene out.pfm --device=scalar --spp=16 --width=64 --height=64
 *
 * Built against the public header and libclpt.so only (make: build/examples/render).
 */
#include <clpt/clpt.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A line that rewrites itself; never cancels. */
static int show_progress(void *user, unsigned done, unsigned total)
{
    (void)user;
    fprintf(stderr, "\rrendering: %u of %u samples per pixel", done, total);
    return 0;
}

/* PFM: a text header, then the rows bottom to top as little-endian floats. */
static int write_pfm(const char *path, const float *rgb, unsigned w, unsigned h)
{
    FILE *f = fopen(path, "wb");
    if (!f) return -1;
    fprintf(f, "PF\n%u %u\n-1.0\n", w, h);
    for (unsigned y = h; y-- > 0;) fwrite(rgb + (size_t)y * w * 3, sizeof *rgb, (size_t)w * 3, f);
    return fclose(f) == 0 ? 0 : -1;
}

/* "--name=value" arguments: the devices, scene edits, and settings. */
static clpt_status apply_arguments(clpt_context *ctx, clpt_scene *scene, clpt_settings *set, int argc, char **argv)
{
    clpt_status st = CLPT_OK;
    for (int i = 3; i < argc && st == CLPT_OK; i++) {
        char name[64];
        const char *eq = strchr(argv[i], '=');
        if (strncmp(argv[i], "--", 2) != 0 || !eq || (size_t)(eq - argv[i]) >= sizeof name) {
            fprintf(stderr, "render: expected --NAME=VALUE, got '%s'\n", argv[i]);
            return CLPT_ERROR_USAGE;
        }
        snprintf(name, sizeof name, "%.*s", (int)(eq - argv[i] - 2), argv[i] + 2);
        const char *value = eq + 1, *kv = strchr(value, '=');
        if (strcmp(name, "device") == 0) {
            st = clpt_context_set_devices(ctx, value);
        } else if (strcmp(name, "set") == 0 && kv) {
            char key[256];
            snprintf(key, sizeof key, "%.*s", (int)(kv - value), value);
            st = clpt_scene_set(scene, key, kv + 1);
        } else {
            st = clpt_settings_set(set, name, value);
        }
    }
    return st;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: render SCENE OUT.pfm [--device=SPEC] [--set=KEY=VALUE] [--NAME=VALUE ...]\n");
        return 2;
    }
    clpt_context *ctx = clpt_context_create();
    if (!ctx) return 1;
    clpt_settings *set = clpt_settings_create(ctx);
    clpt_scene *scene = NULL;
    float *rgb = NULL;
    clpt_status st = set ? clpt_scene_load(ctx, argv[1], &scene) : CLPT_ERROR_INTERNAL;
    if (st == CLPT_OK) st = apply_arguments(ctx, scene, set, argc, argv);
    unsigned w = 0, h = 0;
    if (st == CLPT_OK) st = clpt_render_size(scene, set, &w, &h);
    if (st == CLPT_OK && !(rgb = malloc((size_t)w * h * 3 * sizeof *rgb))) st = CLPT_ERROR_INTERNAL;
    clpt_image img = { w, h, rgb, NULL, NULL, NULL, 0 };
    if (st == CLPT_OK) st = clpt_render(scene, set, &img, show_progress, NULL);
    if (st == CLPT_OK || st == CLPT_INTERRUPTED) {
        fprintf(stderr, "\nrender: %ux%u, %u spp -> %s\n", w, h, img.spp, argv[2]);
        if (write_pfm(argv[2], rgb, w, h) != 0) {
            fprintf(stderr, "render: cannot write '%s'\n", argv[2]);
            st = CLPT_ERROR_IO;
        }
    } else if (st != CLPT_OK) {
        fprintf(stderr, "render: error: %s\n", clpt_last_error(ctx));
    }
    free(rgb);
    clpt_scene_free(scene);
    clpt_settings_free(set);
    clpt_context_free(ctx);
    return (int)st;
}
