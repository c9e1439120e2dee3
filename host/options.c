/* options.c — command-line parsing, strict: every value is checked whole and in range. */
#include "options.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

void options_print_help(FILE *f)
{
    fputs(
"usage: clpt [options] SCENE\n"
"\n"
"Renders SCENE (a scene file, see docs/scene-format.md) with a path tracer whose\n"
"kernels run on OpenCL devices (GPUs, or CPUs through PoCL) and on a scalar C device.\n"
"\n"
"Output and image:\n"
"  -o, --output FILE          image to write: .png (8-bit sRGB), .ppm (8-bit sRGB) or\n"
"                             .pfm (linear float); default: SCENE's name with .png,\n"
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

Status options_parse(int argc, char **argv, Options *o, Error *err)
{
    memset(o, 0, sizeof *o);
    o->spp = o->width = o->height = o->seed = o->max_depth = -1;
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
            { "--spp", 1, 1000000, &o->spp },
            { "--width", 1, 16384, &o->width },
            { "--height", 1, 16384, &o->height },
            { "--seed", 0, 4294967295L, &o->seed },
            { "--max-depth", 0, 1024, &o->max_depth },
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
