/* options.c — command-line parsing, strict: every value is checked whole and in range. */
#include "options.h"

#include "course_args.h"

#include "device/device.h"
#include "io/scene_load.h"
#include "base/limit.h"
#include "types.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Every line within 80 columns (tests/test_cli.c checks): a terminal's width. */
void options_print_help(FILE *f)
{
    fputs(
"usage: clpt [options] SCENE\n"
"       clpt -size W H -input SCENE -output FILE [-normals FILE]\n"
"            [-depth NEAR FAR FILE] [-bounces N] [-shadows] [--options]\n"
"       clpt SCENE OUT.bmp [--options]\n"
"\n"
"Renders SCENE (a scene file, see docs/scene-format.md, or a scene of the\n"
"MIT 6.837 course family, see docs/classic-format.md) with a path tracer or a\n"
"classic Whitted ray tracer whose kernels run on OpenCL devices (GPUs, or CPUs\n"
"through PoCL) and on a scalar C device. SCENE may also be a mesh (.obj or\n"
".ply): it is shown lit by a sky and a sun, seen by a camera that frames it\n"
"(docs/meshes.md); or a glTF 2.0 file (.gltf, .glb), seen through its own\n"
"camera when it has one (docs/gltf.md).\n"
"\n"
"The second and third forms are the command lines of the courses' reference ray\n"
"tracers (MIT 6.837, recognised by a first argument -size or -input; Tsinghua,\n"
"two arguments, the second an image name): they render as the course program\n"
"does (whitted, one ray per pixel centre, no gamma, -bounces N mirror/refraction\n"
"bounces, default 0; no shadows unless -shadows). -depth draws NEAR black and\n"
"FAR white. See docs/classic-format.md.\n"
"\n",
        f);
    /* several literals: C99 compilers need only support 4095 characters in one */
    fputs(
"Output and image:\n"
"  -o, --output FILE          image to write: .png, .ppm or .bmp (8-bit sRGB)\n"
"                             or .pfm, .exr (half; see --exr-float) or .hdr\n"
"                             (linear float); default: the file a pbrt\n"
"                             scene's Film names, else SCENE's name\n"
"                             with .png, in the current folder. Written\n"
"                             atomically; a symlink is followed and an\n"
"                             existing file keeps its permissions; only a\n"
"                             regular file is replaced (a FIFO or device\n"
"                             is refused). Checked before rendering\n"
"      --spp N                samples per pixel (overrides the scene)\n"
"      --width N              image width in pixels (overrides the scene)\n"
"      --height N             image height in pixels (overrides the scene)\n"
"      --seed N               random seed; the same seed gives the same image\n"
"                             on any devices and batch sizes\n"
"      --max-depth N          longest path, in bounces (overrides the scene)\n"
"      --split N              path tracer: shade each camera sample's first hit\n"
"                             N times, each with its own light sample and\n"
"                             continuation weighted 1/N, sharing the camera ray\n"
"                             (1..64; overrides the scene's image split; 1: none,\n"
"                             the default)\n"
"      --sampler sobol|independent\n"
"                             random numbers: Owen-scrambled Sobol points\n"
"                             (default; less noise) or independent ones\n"
"                             (clpt's earlier sampler, the same images)\n"
"      --accel bvh|kdtree     the tree rays find primitives through: an 8-wide\n"
"                             BVH (default; faster) or the SAH kd-tree\n"
"      --time-limit SECONDS   stop starting new batches after this long; the\n"
"                             image holds the whole batches finished by then\n"
"                             (none: the output is left alone, exit status 7)\n"
"      --progressive-output SECONDS\n"
"                             rewrite the output image every SECONDS during\n"
"                             the render\n"
"      --gamma srgb|none      8-bit images with the sRGB curve or without\n"
"                             (linear values times 255); default: srgb, none\n"
"                             for classic scenes\n"
"      --exr-float            EXR channels as 32-bit floats (default: half)\n"
"      --aov LIST             also write auxiliary images of the first hit,\n"
"                             comma-separated: normal (as colours), depth\n"
"                             (grey: near white, far black), albedo; to\n"
"                             OUTPUT-normal.png etc.; an .exr output holds\n"
"                             them as channels normal.X/Y/Z (signed), Z\n"
"                             (distance) and albedo.R/G/B instead. Depth\n"
"                             in .pfm and .exr is the distance, +inf where\n"
"                             nothing is hit; in 8-bit images misses are\n"
"                             black\n"
"      --depth-range NEAR,FAR the depth image is linear from white at NEAR to\n"
"                             black at FAR (NEAR > FAR inverts it; default:\n"
"                             inverse distance, nearest hit white). Needs\n"
"                             --aov depth\n"
"\n",
        f);
    fputs(
"Checkpoints (docs/checkpoint.md):\n"
"      --checkpoint FILE      save the render's state to FILE (atomically)\n"
"                             every --checkpoint-interval seconds, on\n"
"                             Ctrl-C/SIGTERM and at the end\n"
"      --checkpoint-interval SECONDS\n"
"                             seconds between checkpoints (default 60)\n"
"      --resume FILE          continue the render saved in FILE: only the\n"
"                             samples not in it are rendered, and the image is\n"
"                             the same bits as an uninterrupted render's. The\n"
"                             scene and settings must be the ones it was made\n"
"                             with (else exit status 3). Checkpoints go on\n"
"                             into FILE unless --checkpoint names another file\n"
"      --sample-range A:B     render only samples A..B-1 of every pixel: a part\n"
"                             of the render for 'clpt merge' (with --checkpoint\n"
"                             PART); -o gets the part's own image\n"
"\n",
        f);
    fputs(
"Merging parts (docs/distributed.md):\n"
"  clpt merge -o OUT PART...  add the films of --sample-range parts of one\n"
"                             render exactly: OUT is the same bits as one\n"
"                             process rendering every sample. Parts that\n"
"                             overlap, leave samples out or belong to other\n"
"                             renders are refused (exit status 3). Also\n"
"                             --checkpoint FILE, --gamma srgb|none, -q\n"
"\n"
"MPI (mpirun -np N clpt SCENE ..., or srun; docs/distributed.md):\n"
"                             one image from N processes, each on its own\n"
"                             devices (--device applies to each); rank 0\n"
"                             hands out batches, writes every output and\n"
"                             prints; the image is the same bits as one\n"
"                             process's. Not with --adaptive or --aov\n"
"      --mpi-broadcast        rank 0 reads the scene and sends it to the\n"
"                             others (default: every rank reads SCENE, which\n"
"                             must then be on a shared path)\n"
"      --mpi-timeout SECONDS  give a rank up after this long without a word\n"
"                             from it (default 30); its batches go to others.\n"
"                             Also how long the job may take to start\n"
"\n"
"Scene and integrator:\n"
"      --format auto|clpt|classic|pbrt\n"
"                             scene file format; default: told from the content\n"
"                             (pbrt: pbrt-v4 scenes, see docs/pbrt.md)\n"
"      --camera N|NAME        glTF: look through camera N (from 0) or the camera\n"
"                             (or camera node) named NAME; default: the first\n"
"      --integrator path|whitted\n"
"                             path tracing (default) or the classic ray tracer\n"
"                             (the default for classic scenes): Phong shading,\n"
"                             hard shadows (see --shadows), mirror and\n"
"                             refraction rays up to --max-depth; one ray\n"
"                             through each pixel centre unless --spp N\n"
"                             (jittered; an m x m grid when N = m*m)\n"
"      --shadows on|off       whether lights can be blocked (shadow rays), in\n"
"                             both integrators; default: on, off for classic\n"
"                             scenes (as the course ray casters)\n"
"      --adaptive THRESHOLD   whitted: after the first pass, render\n"
"                             --adaptive-spp more samples in each pixel that\n"
"                             differs from a neighbour by more than THRESHOLD\n"
"                             (0..1) in some channel\n"
"      --adaptive-spp N       extra samples per such pixel (default 16; needs\n"
"                             --adaptive)\n"
"\n",
        f);
    fputs(
"Interactive viewer (docs/viewer.md):\n"
"  -i, --interactive          show SCENE in a window and render it\n"
"                             progressively while the camera moves (needs a\n"
"                             display: else exit status 5). Keys: W/A/S/D\n"
"                             move, R/F or Q/E up/down, drag the mouse to\n"
"                             look, wheel forward/back, Z/X field of view,\n"
"                             Up/Down focus distance, Right/Left aperture,\n"
"                             +/- exposure, Space pause, C save the image\n"
"                             (SCENE-view-NNN.png and .pfm, never over an\n"
"                             earlier save), P print the camera as a scene\n"
"                             block, H help, F11 full screen, Esc quit.\n"
"                             A view renders up to --spp (else the scene's\n"
"                             spp) samples per pixel\n"
"\n"
"Devices:\n"
"      --list-devices         print every OpenCL platform and device with its\n"
"                             index, and the scalar device, then exit\n"
"      --device SPEC          devices to render with, comma-separated: an\n"
"                             OpenCL device's index from --list-devices,\n"
"                             'all', 'gpu', 'cpu' (OpenCL CPU devices),\n"
"                             'scalar', or part of a device or platform\n"
"                             name. Default: every OpenCL GPU, else the\n"
"                             OpenCL CPU devices, else the scalar device\n"
"      --threads N            worker threads of the scalar device (default:\n"
"                             all cores)\n"
"\n",
          f);
    fputs(
"Reporting:\n"
"      --stats                print scene, tree (BVH or kd-tree), kernel\n"
"                             build, OpenCL wave (size, how it runs) and\n"
"                             per-device statistics to stdout\n"
"      --profile              --stats, and where each device's time goes: ray\n"
"                             generation, traversal, shading, shadow rays,\n"
"                             film, queues, host waits (slows rendering)\n"
"  -q, --quiet                no progress bar and no summary line\n"
"  -h, --help                 print this help and exit\n"
"      --version              print the version and exit\n"
"\n"
"Developer options:\n"
"      --kernel-dir DIR       compile the kernels from DIR/entry.cl instead of\n"
"                             the copy built into the program (no kernel cache)\n"
"      --batch N              fixed batch size in samples per pixel (default:\n"
"                             adaptive, about 0.25 s of work per batch)\n"
"      --wave-paths N         paths per OpenCL wave (default: 2^22 on GPUs of\n"
"                             8 GiB or more when it fits in half their\n"
"                             memory, else 2^20; on CPUs 2^16 per compute\n"
"                             unit up to 2^21 where it fits in half\n"
"                             the memory, else 2^16; 2^14 with\n"
"                             --interactive)\n"
"      --wave-launch counted|bounded|megakernel\n"
"                             how an OpenCL device runs a wave: 'counted'\n"
"                             launches each bounce over the live paths the\n"
"                             device counted, read back first; 'bounded' all\n"
"                             bounces at once over the wave's size, the kernels\n"
"                             stopping at the count on the device (GPUs'\n"
"                             default); 'megakernel' one kernel that runs each\n"
"                             path to its end (CPUs' default; counted with\n"
"                             --profile)\n"
"\n"
"Environment:\n"
"  CLPT_CACHE_DIR             where compiled kernels are cached (default:\n"
"                             $XDG_CACHE_HOME/clpt or ~/.cache/clpt)\n"
"\n"
"Exit status (docs/exit-codes.md):\n"
"  0  success                 4  I/O error (a file could not be read or\n"
"  1  internal error             written, or standard output failed)\n"
"  2  usage error             5  device error (no usable device, or every\n"
"  3  input error (bad scene,    device failed; --interactive: no display)\n"
"     mesh or checkpoint      6  interrupted (SIGINT/SIGTERM): what was\n"
"     file, or a checkpoint      finished was written\n"
"     of another render)      7  nothing rendered: --time-limit ran out before\n"
"                                the first batch; the output was left alone\n",
        f);
}

/* strtol and strtod skip leading blanks: " 5" would be 5, while "5 " is refused. A
 * number is refused with a blank at either end, so that what was typed is what counts. */
static int starts_blank(const char *s)
{
    return isspace((unsigned char)s[0]);
}

static Status parse_long(const char *flag, const char *s, long lo, long hi, long *out, Error *err)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (!*s || *end || errno || starts_blank(s))
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
    if (!*s || *end || errno || starts_blank(s) || !isfinite(v) || v <= 0.0)
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

/* --depth-range NEAR,FAR */
static Status parse_depth_range(const char *v, Options *o, Error *err)
{
    char *end;
    errno = 0;
    double lo = strtod(v, &end), hi = 0.0;
    int ok = end != v && *end == ',' && !errno && !starts_blank(v);
    if (ok) {
        const char *second = end + 1;
        hi = strtod(second, &end);
        ok = end != second && !*end && !errno && !starts_blank(second);
    }
    /* NEAR > FAR turns the ramp round: --depth-range 18,8 is the courses' -depth 8 18
     * (near black, far white) */
    if (!ok || !isfinite(lo) || !isfinite(hi) || !(lo >= 0.0) || !(hi >= 0.0) || !(hi != lo))
        return error_set(err, ST_USAGE, "--depth-range expects NEAR,FAR, two different distances >= 0 "
                         "(NEAR > FAR inverts the grey), got '%s'", v);
    o->depth_near = lo;
    o->depth_far = hi;
    return ST_OK;
}

/* --sample-range A:B, 0 <= A < B <= CLPT_MAX_SPP (B is checked against the render's
 * samples per pixel once the scene is read). */
static Status parse_sample_range(const char *v, Options *o, Error *err)
{
    char *end;
    errno = 0;
    long a = strtol(v, &end, 10), b = -1;
    int ok = end != v && *end == ':' && !errno && v[0] != '-' && v[0] != '+' && !starts_blank(v);
    if (ok) {
        const char *second = end + 1;
        b = strtol(second, &end, 10);
        ok = end != second && !*end && !errno && second[0] != '-' && second[0] != '+' && !starts_blank(second);
    }
    if (!ok || a < 0 || b <= a || b > CLPT_MAX_SPP)
        return error_set(err, ST_USAGE, "--sample-range expects A:B, sample indices with 0 <= A < B <= %d, got '%s'",
                         CLPT_MAX_SPP, v);
    o->range_first = a;
    o->range_end = b;
    return ST_OK;
}

static Status parse_adaptive(const char *v, Options *o, Error *err)
{
    char *end;
    errno = 0;
    double t = strtod(v, &end);
    if (!*v || *end || errno || starts_blank(v) || !(t > 0.0 && t <= 1.0))
        return error_set(err, ST_USAGE, "--adaptive expects a threshold in (0, 1], got '%s'", v);
    o->adaptive = t;
    return ST_OK;
}

/* One of `names` (NULL-terminated): its index into *out. */
static Status parse_choice(const char *flag, const char *v, const char *const *names, const int *values,
                           const char *expected, int *out, Error *err)
{
    for (size_t i = 0; names[i]; i++)
        if (strcmp(v, names[i]) == 0) {
            *out = values[i];
            return ST_OK;
        }
    return error_set(err, ST_USAGE, "%s expects %s, got '%s'", flag, expected, v);
}

/* Flags without a value: 1 when `a` is one (and it is set). */
static int options_set_switch(const char *a, Options *o)
{
    struct { const char *name, *alias; int *dst; } switches[] = {
        { "--help", "-h", &o->help },      { "--version", NULL, &o->version },
        { "--list-devices", NULL, &o->list_devices }, { "--stats", NULL, &o->stats },
        { "--quiet", "-q", &o->quiet },    { "--mpi-broadcast", NULL, &o->mpi_broadcast },
        { "--interactive", "-i", &o->interactive }, { "--profile", NULL, &o->profile },
        { "--exr-float", NULL, &o->exr_float },
    };
    for (size_t k = 0; k < sizeof switches / sizeof switches[0]; k++)
        if (strcmp(a, switches[k].name) == 0 || (switches[k].alias && strcmp(a, switches[k].alias) == 0)) {
            *switches[k].dst = 1;
            return 1;
        }
    return 0;
}

/* Flags whose value is a file, folder or device list, kept as given. */
static Status options_set_name(const char *a, const char *v, Options *o, int *found, Error *err)
{
    struct { const char *name, *alias, *what; const char **dst; } names[] = {
        { "--output", "-o", "file name", &o->output },
        { "--checkpoint", NULL, "file name", &o->checkpoint_path },
        { "--resume", NULL, "file name", &o->resume_path },
        { "--device", NULL, "device list", &o->device_spec },
        { "--kernel-dir", NULL, "folder name", &o->kernel_dir },
        { "--camera", NULL, "camera index or name", &o->camera },
    };
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        if (strcmp(a, names[k].name) != 0 && !(names[k].alias && strcmp(a, names[k].alias) == 0)) continue;
        *found = 1;
        if (!*v) return error_set(err, ST_USAGE, "%s needs a %s", a, names[k].what);
        *names[k].dst = v;
        return ST_OK;
    }
    return ST_OK;
}

/* Flags whose value is a number. */
static Status options_set_number(const char *a, const char *v, Options *o, int *found, Error *err)
{
    long n;
    Status st;
    struct { const char *name; long lo, hi; long *dst; } longs[] = {
        { "--spp", 1, CLPT_MAX_SPP, &o->spp },
        { "--width", 1, CLPT_MAX_IMAGE_SIDE, &o->width },
        { "--height", 1, CLPT_MAX_IMAGE_SIDE, &o->height },
        { "--seed", 0, 4294967295L, &o->seed },
        { "--max-depth", 0, CLPT_MAX_DEPTH, &o->max_depth },
        { "--split", 1, CLPT_MAX_SPLIT, &o->split },
    };
    struct { const char *name; long lo, hi; unsigned *dst; } uints[] = {
        { "--batch", 1, 1000000, &o->batch },
        { "--wave-paths", 1, 1L << 26, &o->wave_paths },
        { "--adaptive-spp", 1, 65536, &o->adaptive_spp },
    };
    struct { const char *name; double *dst; } seconds[] = {
        { "--checkpoint-interval", &o->checkpoint_seconds },
        { "--time-limit", &o->time_limit },
        { "--progressive-output", &o->progressive_seconds },
        { "--mpi-timeout", &o->mpi_timeout },
    };
    *found = 1;
    for (size_t k = 0; k < sizeof longs / sizeof longs[0]; k++)
        if (strcmp(a, longs[k].name) == 0) return parse_long(a, v, longs[k].lo, longs[k].hi, longs[k].dst, err);
    for (size_t k = 0; k < sizeof uints / sizeof uints[0]; k++)
        if (strcmp(a, uints[k].name) == 0) {
            if ((st = parse_long(a, v, uints[k].lo, uints[k].hi, &n, err))) return st;
            *uints[k].dst = (unsigned)n;
            return ST_OK;
        }
    for (size_t k = 0; k < sizeof seconds / sizeof seconds[0]; k++)
        if (strcmp(a, seconds[k].name) == 0) return parse_seconds(a, v, seconds[k].dst, err);
    if (strcmp(a, "--threads") == 0) {
        if ((st = parse_long(a, v, 1, 256, &n, err))) return st;
        o->threads = (int)n;
        return ST_OK;
    }
    if (strcmp(a, "--adaptive") == 0) return parse_adaptive(v, o, err);
    if (strcmp(a, "--sample-range") == 0) return parse_sample_range(v, o, err);
    if (strcmp(a, "--depth-range") == 0) return parse_depth_range(v, o, err);
    *found = 0;
    return ST_OK;
}

/* Flags whose value is a word from a list. */
static Status options_set_choice(const char *a, const char *v, Options *o, int *found, Error *err)
{
    static const char *const integrators[] = { "path", "whitted", NULL };
    static const int integrator_values[] = { INTEGRATOR_PATH, INTEGRATOR_WHITTED };
    static const char *const formats[] = { "auto", "clpt", "classic", "pbrt", NULL };
    static const int format_values[] = { SCENE_FORMAT_AUTO, SCENE_FORMAT_CLPT, SCENE_FORMAT_CLASSIC,
                                         SCENE_FORMAT_PBRT };
    static const char *const gammas[] = { "srgb", "none", NULL };
    static const int gamma_values[] = { 0, 1 };
    static const char *const on_off[] = { "on", "off", NULL };
    static const int on_off_values[] = { 1, 0 };
    static const char *const samplers[] = { "sobol", "independent", NULL };
    static const int sampler_values[] = { SAMPLER_SOBOL, SAMPLER_INDEPENDENT };
    static const char *const accels[] = { "bvh", "kdtree", NULL };
    static const int accel_values[] = { ACCEL_BVH, ACCEL_KDTREE };
    static const char *const launches[] = { "counted", "bounded", "megakernel", NULL };
    static const int launch_values[] = { WAVE_LAUNCH_COUNTED, WAVE_LAUNCH_BOUNDED, WAVE_LAUNCH_MEGAKERNEL };
    *found = 1;
    if (strcmp(a, "--integrator") == 0)
        return parse_choice(a, v, integrators, integrator_values, "'path' or 'whitted'", &o->integrator, err);
    if (strcmp(a, "--format") == 0)
        return parse_choice(a, v, formats, format_values, "'auto', 'clpt', 'classic' or 'pbrt'", &o->format, err);
    if (strcmp(a, "--gamma") == 0)
        return parse_choice(a, v, gammas, gamma_values, "'srgb' or 'none'", &o->gamma, err);
    if (strcmp(a, "--shadows") == 0)
        return parse_choice(a, v, on_off, on_off_values, "'on' or 'off'", &o->shadows, err);
    if (strcmp(a, "--sampler") == 0)
        return parse_choice(a, v, samplers, sampler_values, "'sobol' or 'independent'", &o->sampler, err);
    if (strcmp(a, "--accel") == 0)
        return parse_choice(a, v, accels, accel_values, "'bvh' or 'kdtree'", &o->accel, err);
    if (strcmp(a, "--wave-launch") == 0)
        return parse_choice(a, v, launches, launch_values, "'counted', 'bounded' or 'megakernel'", &o->wave_launch,
                            err);
    if (strcmp(a, "--aov") == 0) return options_parse_aovs(v, &o->aovs, err);
    *found = 0;
    return ST_OK;
}

/* A flag that takes a value, with its value (the next argument, or after '=' in
 * --flag=value). *found is 0 when `a` is no such flag. */
static Status options_set_value(const char *a, const char *v, Options *o, int *found, Error *err)
{
    Status st = options_set_name(a, v, o, found, err);
    if (!*found) st = options_set_number(a, v, o, found, err);
    if (!*found) st = options_set_choice(a, v, o, found, err);
    return st;
}

static void options_defaults(Options *o)
{
    memset(o, 0, sizeof *o);
    o->spp = o->width = o->height = o->seed = o->max_depth = o->split = -1;
    o->range_first = o->range_end = -1;
    o->integrator = -1;
    o->gamma = -1;
    o->shadows = -1;
    o->sampler = -1;
    o->accel = -1;
    o->format = SCENE_FORMAT_AUTO;
    o->adaptive_spp = 0;   /* not given; 16 once options_finish has checked */
}

/* argv[*i]: a switch, a flag and its value (advancing *i), or the scene. */
static Status options_parse_arg(int argc, char **argv, int *i, Options *o, Error *err)
{
    const char *a = argv[*i];
    /* --flag=value is accepted too */
    char flag[64];
    const char *value = NULL;
    const char *eq = a[0] == '-' && a[1] == '-' ? strchr(a, '=') : NULL;
    if (eq) {
        size_t n = (size_t)(eq - a);
        if (n >= sizeof flag) return error_set(err, ST_USAGE, "unknown option '%s' (see --help)", a);
        memcpy(flag, a, n);
        flag[n] = '\0';
        value = eq + 1;
        a = flag;
    }
    if (!value && options_set_switch(a, o)) return ST_OK;
    /* a flag that takes a value takes the next argument when not given one with '=' */
    const char *next = *i + 1 < argc ? argv[*i + 1] : NULL;
    int found = 0;
    Status st = options_set_value(a, value ? value : (next ? next : ""), o, &found, err);
    if (found) {
        if (!value && !next) return error_set(err, ST_USAGE, "%s needs a value", a);
        if (!value) ++*i;
        return st;
    }
    if (value || (a[0] == '-' && a[1] != '\0'))
        return error_set(err, ST_USAGE, "unknown option '%s' (see --help)", a);
    if (o->scene_path)
        return error_set(err, ST_USAGE, "more than one scene given: '%s' and '%s'", o->scene_path, a);
    o->scene_path = a;
    return ST_OK;
}

/* The viewer writes no output file of its own (C saves frames) and renders until it is
 * closed: the flags that shape a batch render's files and its end do not apply. */
static Status options_check_interactive(const Options *o, Error *err)
{
    if (!o->interactive) return ST_OK;
    const char *flag = o->output ? "--output" : o->checkpoint_path ? (o->resume_path ? "--resume" : "--checkpoint")
                     : o->time_limit > 0.0 ? "--time-limit" : o->progressive_seconds > 0.0 ? "--progressive-output"
                     : o->aovs ? "--aov" : o->adaptive > 0.0 ? "--adaptive"
                     : o->range_end >= 0 ? "--sample-range" : NULL;
    if (flag)
        return error_set(err, ST_USAGE, "--interactive cannot be combined with %s (the viewer saves frames "
                                        "with the C key; see docs/viewer.md)", flag);
    return ST_OK;
}

/* What depends on several flags. */
static Status options_finish(Options *o, Error *err)
{
    if (o->checkpoint_seconds > 0.0 && !o->checkpoint_path && !o->resume_path)
        return error_set(err, ST_USAGE, "--checkpoint-interval needs --checkpoint FILE (or --resume FILE)");
    if (o->resume_path && !o->checkpoint_path) o->checkpoint_path = o->resume_path;
    if (o->range_end >= 0 && o->adaptive > 0.0)
        return error_set(err, ST_USAGE, "--adaptive cannot be used with --sample-range (it needs the whole image)");
    /* Flags that shape what another flag turns on do nothing alone: said, not ignored
     * (an image rendered without the pass or the depth image the user asked for). */
    if (o->adaptive_spp && !(o->adaptive > 0.0))
        return error_set(err, ST_USAGE, "--adaptive-spp sets the samples of the adaptive pass, which --adaptive "
                         "THRESHOLD turns on; give both, or neither");
    if (!o->adaptive_spp) o->adaptive_spp = 16;
    if (o->depth_near != o->depth_far && !(o->aovs & (1u << INTEGRATOR_AOV_DEPTH)))
        return error_set(err, ST_USAGE, "--depth-range scales the depth image, which --aov depth turns on; "
                         "give both, or neither");
    if (o->checkpoint_seconds <= 0.0) o->checkpoint_seconds = 60.0;
    if (!o->scene_path && !o->help && !o->version && !o->list_devices)
        return error_set(err, ST_USAGE, "no scene given (usage: clpt [options] SCENE; see --help)");
    return options_check_interactive(o, err);
}

Status options_parse(int argc, char **argv, Options *o, Error *err)
{
    options_defaults(o);
    int first = 1;
    CourseStyle course = course_args_style(argc, argv);
    if (course != COURSE_NONE) {
        Status st = course_args_parse(course, argc, argv, o, &first, err);
        if (st) return st;
    }
    for (int i = first; i < argc; i++) {
        Status st = options_parse_arg(argc, argv, &i, o, err);
        if (st) return st;
    }
    return options_finish(o, err);
}
