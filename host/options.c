/* options.c — command-line parsing, strict: every value is checked whole and in range. */
#include "options.h"

#include "io/scene_load.h"
#include "base/limit.h"
#include "types.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void options_print_help(FILE *f)
{
    fputs(
"usage: clpt [options] SCENE\n"
"\n"
"Renders SCENE (a scene file, see docs/scene-format.md, or a scene of the MIT 6.837\n"
"course family, see docs/classic-format.md) with a path tracer or a classic Whitted\n"
"ray tracer whose kernels run on OpenCL devices (GPUs, or CPUs through PoCL) and on a\n"
"scalar C device. SCENE may also be a mesh (.obj or .ply): it is shown lit by a sky\n"
"and a sun, seen by a camera that frames it (docs/meshes.md).\n"
"\n"
"Output and image:\n"
"  -o, --output FILE          image to write: .png, .ppm or .bmp (8-bit sRGB) or .pfm\n"
"                             (linear float); default: SCENE's name with .png,\n"
"                             in the current folder. Written atomically.\n"
"      --spp N                samples per pixel (overrides the scene)\n"
"      --width N              image width in pixels (overrides the scene)\n"
"      --height N             image height in pixels (overrides the scene)\n"
"      --seed N               random seed; the same seed gives the same image on any\n"
"                             devices and batch sizes\n"
"      --max-depth N          longest path, in bounces (overrides the scene)\n"
"      --time-limit SECONDS   stop starting new batches after this long; the image\n"
"                             holds the whole batches finished by then\n"
"      --progressive-output SECONDS\n"
"                             rewrite the output image every SECONDS during the render\n"
"      --gamma srgb|none      8-bit images with the sRGB curve or without (linear\n"
"                             values times 255); default: srgb, none for classic scenes\n"
"      --aov LIST             also write auxiliary images of the first hit, comma-\n"
"                             separated: normal (as colours), depth (grey: near white,\n"
"                             far black), albedo; to OUTPUT-normal.png etc.\n"
"      --depth-range NEAR,FAR the depth image is linear from white at NEAR to black at\n"
"                             FAR (default: inverse distance, nearest hit white)\n"
"\n"
"Checkpoints (docs/checkpoint.md):\n"
"      --checkpoint FILE      save the render's state to FILE (atomically) every\n"
"                             --checkpoint-interval seconds, on Ctrl-C/SIGTERM and at\n"
"                             the end\n"
"      --checkpoint-interval SECONDS\n"
"                             seconds between checkpoints (default 60)\n"
"      --resume FILE          continue the render saved in FILE: only the samples not in\n"
"                             it are rendered, and the image is the same bits as an\n"
"                             uninterrupted render's. The scene and settings must be the\n"
"                             ones it was made with (else exit status 3). Checkpoints go\n"
"                             on into FILE unless --checkpoint names another file\n"
"\n"
"Scene and integrator:\n"
"      --format auto|clpt|classic\n"
"                             scene file format; default: told from the content\n"
"      --integrator path|whitted\n"
"                             path tracing (default) or the classic ray tracer (the\n"
"                             default for classic scenes): Phong shading, hard\n"
"                             shadows, mirror and refraction rays up to --max-depth;\n"
"                             one ray through each pixel centre unless --spp N\n"
"                             (jittered; an m x m grid when N = m*m)\n"
"      --adaptive THRESHOLD   whitted: after the first pass, render --adaptive-spp\n"
"                             more samples in each pixel that differs from a neighbour\n"
"                             by more than THRESHOLD (0..1) in some channel\n"
"      --adaptive-spp N       extra samples per such pixel (default 16)\n"
"\n",
        f);
    /* two literals: C99 compilers need only support 4095 characters in one */
    fputs(
"Devices:\n"
"      --list-devices         print every OpenCL platform and device, and the scalar\n"
"                             device, with their indices, then exit\n"
"      --device SPEC          devices to render with, comma-separated: an index from\n"
"                             --list-devices, 'all', 'gpu', 'cpu' (OpenCL CPU devices),\n"
"                             'scalar', or part of a device or platform name.\n"
"                             Default: every OpenCL GPU, else the OpenCL CPU devices,\n"
"                             else the scalar device\n"
"      --threads N            worker threads of the scalar device (default: all cores)\n"
"\n"
"Reporting:\n"
"      --stats                print scene, kd-tree, kernel build and per-device\n"
"                             statistics to stdout\n"
"  -q, --quiet                no progress bar and no summary line\n"
"  -h, --help                 print this help and exit\n"
"      --version              print the version and exit\n"
"\n"
"Developer options:\n"
"      --kernel-dir DIR       compile the kernels from DIR/entry.cl instead of the copy\n"
"                             built into the program (no kernel cache)\n"
"      --batch N              fixed batch size in samples per pixel (default: adaptive,\n"
"                             about 0.25 s of work per batch)\n"
"      --wave-paths N         paths per OpenCL wave (default: 2^20 on GPUs, 2^16 on CPUs)\n"
"\n"
"Environment:\n"
"  CLPT_CACHE_DIR             where compiled kernels are cached (default:\n"
"                             $XDG_CACHE_HOME/clpt or ~/.cache/clpt)\n"
"\n"
"Exit status:\n"
"  0  success                 3  input error (bad scene, mesh or checkpoint file,\n"
"                                or a checkpoint of another render)\n"
"  1  internal error          4  I/O error (a file could not be read or written)\n"
"  2  usage error             5  device error (no usable device, or every device failed)\n"
"  6  interrupted (SIGINT/SIGTERM): the image so far was written\n",
        f);
}

static Status parse_long(const char *flag, const char *s, long lo, long hi, long *out, Error *err)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (!*s || *end || errno)
        return error_set(err, ST_USAGE, "%s expects an integer, got '%s'", flag, s);
    if (v < lo || v > hi)
        return error_set(err, ST_USAGE, "%s must be between %ld and %ld, got %ld", flag, lo, hi, v);
    *out = v;
    return ST_OK;
}

static Status parse_seconds(const char *flag, const char *s, double *out, Error *err)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (!*s || *end || errno || !isfinite(v) || v <= 0.0)
        return error_set(err, ST_USAGE, "%s expects a positive number of seconds, got '%s'", flag, s);
    *out = v;
    return ST_OK;
}

const char *options_aov_name(unsigned aov)
{
    switch (aov) {
    case INTEGRATOR_AOV_NORMAL: return "normal";
    case INTEGRATOR_AOV_DEPTH: return "depth";
    case INTEGRATOR_AOV_ALBEDO: return "albedo";
    default: return NULL;
    }
}

/* "normal,depth" -> the bits 1 << INTEGRATOR_AOV_NORMAL | 1 << INTEGRATOR_AOV_DEPTH */
static Status options_parse_aovs(const char *list, unsigned *bits, Error *err)
{
    const char *p = list;
    do {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        unsigned found = 0;
        for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO; a++) {
            const char *name = options_aov_name(a);
            if (strlen(name) == len && strncmp(p, name, len) == 0) found = a;
        }
        if (!found)
            return error_set(err, ST_USAGE, "--aov expects a comma-separated list of normal, depth, "
                             "albedo; got '%s'", list);
        *bits |= 1u << found;
        p = end ? end + 1 : NULL;
    } while (p);
    return ST_OK;
}

Status options_parse(int argc, char **argv, Options *o, Error *err)
{
    memset(o, 0, sizeof *o);
    o->spp = o->width = o->height = o->seed = o->max_depth = -1;
    o->integrator = -1;
    o->gamma = -1;
    o->format = SCENE_FORMAT_AUTO;
    o->adaptive_spp = 16;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        /* --flag=value is accepted too */
        char flag[64];
        const char *inline_value = NULL;
        if (a[0] == '-' && a[1] == '-' && strchr(a, '=')) {
            size_t n = (size_t)(strchr(a, '=') - a);
            if (n >= sizeof flag) return error_set(err, ST_USAGE, "unknown option '%s' (see --help)", a);
            memcpy(flag, a, n);
            flag[n] = '\0';
            inline_value = a + n + 1;
            a = flag;
        }
#define IS(name) (strcmp(a, name) == 0)
#define VALUE()                                                                             \
    (inline_value ? inline_value                                                            \
                  : (i + 1 < argc ? argv[++i]                                               \
                                  : (error_set(err, ST_USAGE, "%s needs a value", a), (const char *)NULL)))
        const char *v;
        long n;
        Status st;
        if (IS("-h") || IS("--help")) { o->help = 1; continue; }
        if (IS("--version")) { o->version = 1; continue; }
        if (IS("--list-devices")) { o->list_devices = 1; continue; }
        if (IS("--stats")) { o->stats = 1; continue; }
        if (IS("-q") || IS("--quiet")) { o->quiet = 1; continue; }
        if (IS("-o") || IS("--output")) {
            if (!(v = VALUE())) return ST_USAGE;
            if (!*v) return error_set(err, ST_USAGE, "%s needs a file name", a);
            o->output = v;
            continue;
        }
        if (IS("--device")) { if (!(v = VALUE())) return ST_USAGE; o->device_spec = v; continue; }
        if (IS("--kernel-dir")) { if (!(v = VALUE())) return ST_USAGE; o->kernel_dir = v; continue; }
        if (IS("--checkpoint") || IS("--resume")) {
            if (!(v = VALUE())) return ST_USAGE;
            if (!*v) return error_set(err, ST_USAGE, "%s needs a file name", a);
            *(IS("--resume") ? &o->resume_path : &o->checkpoint_path) = v;
            continue;
        }
        if (IS("--checkpoint-interval")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_seconds(a, v, &o->checkpoint_seconds, err))) return st;
            continue;
        }
        struct { const char *name; long lo, hi; long *dst; } ints[] = {
            { "--spp", 1, CLPT_MAX_SPP, &o->spp },
            { "--width", 1, CLPT_MAX_IMAGE_SIDE, &o->width },
            { "--height", 1, CLPT_MAX_IMAGE_SIDE, &o->height },
            { "--seed", 0, 4294967295L, &o->seed },
            { "--max-depth", 0, CLPT_MAX_DEPTH, &o->max_depth },
        };
        int matched = 0;
        for (size_t k = 0; k < sizeof ints / sizeof ints[0]; k++) {
            if (!IS(ints[k].name)) continue;
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_long(a, v, ints[k].lo, ints[k].hi, ints[k].dst, err))) return st;
            matched = 1;
        }
        if (matched) continue;
        if (IS("--threads")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_long(a, v, 1, 256, &n, err))) return st;
            o->threads = (int)n;
            continue;
        }
        if (IS("--batch")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_long(a, v, 1, 1000000, &n, err))) return st;
            o->batch = (unsigned)n;
            continue;
        }
        if (IS("--wave-paths")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_long(a, v, 1, 1L << 26, &n, err))) return st;
            o->wave_paths = (unsigned)n;
            continue;
        }
        if (IS("--integrator")) {
            if (!(v = VALUE())) return ST_USAGE;
            if (strcmp(v, "path") == 0) o->integrator = INTEGRATOR_PATH;
            else if (strcmp(v, "whitted") == 0) o->integrator = INTEGRATOR_WHITTED;
            else return error_set(err, ST_USAGE, "--integrator expects 'path' or 'whitted', got '%s'", v);
            continue;
        }
        if (IS("--format")) {
            if (!(v = VALUE())) return ST_USAGE;
            if (strcmp(v, "auto") == 0) o->format = SCENE_FORMAT_AUTO;
            else if (strcmp(v, "clpt") == 0) o->format = SCENE_FORMAT_CLPT;
            else if (strcmp(v, "classic") == 0) o->format = SCENE_FORMAT_CLASSIC;
            else return error_set(err, ST_USAGE, "--format expects 'auto', 'clpt' or 'classic', got '%s'", v);
            continue;
        }
        if (IS("--gamma")) {
            if (!(v = VALUE())) return ST_USAGE;
            if (strcmp(v, "srgb") == 0) o->gamma = 0;
            else if (strcmp(v, "none") == 0) o->gamma = 1;
            else return error_set(err, ST_USAGE, "--gamma expects 'srgb' or 'none', got '%s'", v);
            continue;
        }
        if (IS("--aov")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = options_parse_aovs(v, &o->aovs, err))) return st;
            continue;
        }
        if (IS("--adaptive")) {
            if (!(v = VALUE())) return ST_USAGE;
            char *end;
            errno = 0;
            double t = strtod(v, &end);
            if (!*v || *end || errno || !(t > 0.0 && t <= 1.0))
                return error_set(err, ST_USAGE, "--adaptive expects a threshold in (0, 1], got '%s'", v);
            o->adaptive = t;
            continue;
        }
        if (IS("--depth-range")) {
            if (!(v = VALUE())) return ST_USAGE;
            char *end;
            errno = 0;
            double lo = strtod(v, &end), hi = 0.0;
            int ok = end != v && *end == ',' && !errno;
            if (ok) {
                const char *second = end + 1;
                hi = strtod(second, &end);
                ok = end != second && !*end && !errno;
            }
            if (!ok || !isfinite(lo) || !isfinite(hi) || !(lo >= 0.0) || !(hi > lo))
                return error_set(err, ST_USAGE, "--depth-range expects NEAR,FAR with 0 <= NEAR < FAR, got '%s'", v);
            o->depth_near = lo;
            o->depth_far = hi;
            continue;
        }
        if (IS("--adaptive-spp")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_long(a, v, 1, 65536, &n, err))) return st;
            o->adaptive_spp = (unsigned)n;
            continue;
        }
        if (IS("--time-limit")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_seconds(a, v, &o->time_limit, err))) return st;
            continue;
        }
        if (IS("--progressive-output")) {
            if (!(v = VALUE())) return ST_USAGE;
            if ((st = parse_seconds(a, v, &o->progressive_seconds, err))) return st;
            continue;
        }
#undef IS
#undef VALUE
        if (inline_value) return error_set(err, ST_USAGE, "unknown option '%s' (see --help)", a);
        if (a[0] == '-' && a[1] != '\0')
            return error_set(err, ST_USAGE, "unknown option '%s' (see --help)", a);
        if (o->scene_path)
            return error_set(err, ST_USAGE, "more than one scene given: '%s' and '%s'", o->scene_path, a);
        o->scene_path = a;
    }
    if (o->checkpoint_seconds > 0.0 && !o->checkpoint_path && !o->resume_path)
        return error_set(err, ST_USAGE, "--checkpoint-interval needs --checkpoint FILE (or --resume FILE)");
    if (o->resume_path && !o->checkpoint_path) o->checkpoint_path = o->resume_path;
    if (o->checkpoint_seconds <= 0.0) o->checkpoint_seconds = 60.0;
    if (!o->scene_path && !o->help && !o->version && !o->list_devices)
        return error_set(err, ST_USAGE, "no scene given (usage: clpt [options] SCENE; see --help)");
    return ST_OK;
}
