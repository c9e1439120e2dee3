/* options.c — command-line parsing, strict: every value is checked whole and in range.
 *
 * OPTIONS(X) below is THE list of flags (as kernels/scene_buffers.h is of the scene
 * buffers): the parser, the flag lines of --help and the choices an error message
 * lists are all generated from it. A new flag is one entry there (and its field in
 * Options, option_values.h). */
#include "options.h"

#include "course_args.h"

#include "device/device.h"
#include "io/image_write.h"
#include "io/scene_load.h"
#include "io/view_transform.h"
#include "render/passes.h"
#include "base/limit.h"
#include "types.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/*
 * OPTIONS(X) calls X(section, kind, field, name, alias, metavar, extra, help) once per
 * flag, in the order of --help:
 *   section  the --help section it is listed in (HELP_section below)
 *   kind     how its value is read: OPTION_kind (options.h)
 *   field    the member of Options it sets (its type is checked against the kind; a
 *            CUSTOM flag's function may set more than this one)
 *   name, alias  "--output" and "-o" (NULL: no short form)
 *   metavar  its value's name in --help ("FILE"); NULL for a switch, and for a choice,
 *            whose words are listed instead ("bvh|kdtree")
 *   extra    NONE, or what the kind needs: WHAT("file name") for TEXT (the error
 *            message's "needs a file name"), RANGE(lo, hi) for LONG/UINT/INT, ONE_OF(
 *            { "word", value }, ...) for CHOICE, PARSE(function) for CUSTOM. A SWITCH
 *            with ONE_OF also takes a word after '=' (--stats=json; alone: 1)
 *   help     its --help text, '\n' between lines: each line within 80 columns once
 *            indented to column 29 (tests/test_cli.c checks)
 */
#define OPTIONS(X) \
    X(OUTPUT, TEXT, output, "--output", "-o", "FILE", WHAT("file name"), \
        "image to write: .png, .ppm or .bmp (8-bit sRGB)\n" \
        "or .pfm, .exr (half; see --exr-float) or .hdr\n" \
        "(linear float); default: the file a pbrt\n" \
        "scene's Film names, else SCENE's name\n" \
        "with .png, in the current folder. Written\n" \
        "atomically; a symlink is followed and an\n" \
        "existing file keeps its permissions; only a\n" \
        "regular file is replaced (a FIFO or device\n" \
        "is refused). Checked before rendering.\n" \
        "'-' writes PNG to standard output, FORMAT:-\n" \
        "(exr:-, pfm:-, ppm:-, bmp:-, hdr:-) that format") \
    X(OUTPUT, LONG, spp, "--spp", NULL, "N", RANGE(1, CLPT_MAX_SPP), \
        "samples per pixel (overrides the scene)") \
    X(OUTPUT, LONG, width, "--width", NULL, "N", RANGE(1, CLPT_MAX_IMAGE_SIDE), \
        "image width in pixels (overrides the scene)") \
    X(OUTPUT, LONG, height, "--height", NULL, "N", RANGE(1, CLPT_MAX_IMAGE_SIDE), \
        "image height in pixels (overrides the scene)") \
    X(OUTPUT, LONG, seed, "--seed", NULL, "N", RANGE(0, 4294967295L), \
        "random seed; the same seed gives the same image\n" \
        "on any devices and batch sizes") \
    X(OUTPUT, LONG, max_depth, "--max-depth", NULL, "N", RANGE(0, CLPT_MAX_DEPTH), \
        "longest path, in bounces (overrides the scene)") \
    X(OUTPUT, LONG, split, "--split", NULL, "N", RANGE(1, CLPT_MAX_SPLIT), \
        "path tracer: shade each camera sample's first hit\n" \
        "N times, each with its own light sample and\n" \
        "continuation weighted 1/N, sharing the camera ray\n" \
        "(1..64; overrides the scene's image split; 1: none,\n" \
        "the default)") \
    X(OUTPUT, CHOICE, sampler, "--sampler", NULL, NULL, \
        ONE_OF({ "sobol", SAMPLER_SOBOL }, { "independent", SAMPLER_INDEPENDENT }), \
        "random numbers: Owen-scrambled Sobol points\n" \
        "(default; less noise) or independent ones\n" \
        "(clpt's earlier sampler, the same images)") \
    X(OUTPUT, CHOICE, accel, "--accel", NULL, NULL, ONE_OF({ "bvh", ACCEL_BVH }, { "kdtree", ACCEL_KDTREE }), \
        "the tree rays find primitives through: an 8-wide\n" \
        "BVH (default; faster) or the SAH kd-tree") \
    X(OUTPUT, SECONDS, time_limit, "--time-limit", NULL, "SECONDS", NONE, \
        "stop starting new batches after this long; the\n" \
        "image holds the whole batches finished by then\n" \
        "(none: the output is left alone, exit status 7)") \
    X(OUTPUT, SECONDS, progressive_seconds, "--progressive-output", NULL, "SECONDS", NONE, \
        "rewrite the output image every SECONDS during\n" \
        "the render") \
    X(OUTPUT, CHOICE, gamma, "--gamma", NULL, NULL, ONE_OF({ "srgb", 0 }, { "none", 1 }), \
        "8-bit images with the sRGB curve or without\n" \
        "(linear values times 255); default: srgb, none\n" \
        "for classic scenes") \
    X(OUTPUT, CHOICE, view, "--view", NULL, NULL, ONE_OF({ "standard", VIEW_STANDARD }, { "agx", VIEW_AGX }, { "filmic", VIEW_FILMIC }), \
        "how 8-bit images form the picture: standard (the\n" \
        "values clipped at 1; default), agx (Blender 4's\n" \
        "AgX) or filmic (Hable's filmic curve); see\n" \
        "docs/views.md. Not for float outputs") \
    X(OUTPUT, CUSTOM, exposure, "--exposure", NULL, "EV", PARSE(parse_exposure), \
        "scale 8-bit images by 2^EV before the view\n" \
        "(-32..32; default 0). Not for float outputs") \
    X(OUTPUT, SWITCH, exr_float, "--exr-float", NULL, NULL, NONE, \
        "EXR channels as 32-bit floats (default: half)") \
    X(OUTPUT, CUSTOM, aovs, "--aov", NULL, "LIST", PARSE(parse_aovs), \
        "also write auxiliary images of the first hit,\n" \
        "comma-separated: normal (as colours), depth\n" \
        "(grey: near white, far black), albedo; to\n" \
        "OUTPUT-normal.png etc.; an .exr output holds\n" \
        "them as channels normal.X/Y/Z (signed), Z\n" \
        "(distance) and albedo.R/G/B instead. Depth\n" \
        "in .pfm and .exr is the distance (32-bit\n" \
        "float), +inf where nothing is hit; in 8-bit\n" \
        "images misses are black. Normals in .pfm are\n" \
        "signed, as in .exr") \
    X(OUTPUT, CUSTOM, depth_near, "--depth-range", NULL, "NEAR,FAR", PARSE(parse_depth_range), \
        "the depth image is linear from white at NEAR to\n" \
        "black at FAR (NEAR > FAR inverts it; default:\n" \
        "inverse distance, nearest hit white). Needs\n" \
        "--aov depth") \
    X(CHECKPOINT, TEXT, checkpoint_path, "--checkpoint", NULL, "FILE", WHAT("file name"), \
        "save the render's state to FILE (atomically)\n" \
        "every --checkpoint-interval seconds, on\n" \
        "Ctrl-C/SIGTERM and at the end") \
    X(CHECKPOINT, SECONDS, checkpoint_seconds, "--checkpoint-interval", NULL, "SECONDS", NONE, \
        "seconds between checkpoints (default 60)") \
    X(CHECKPOINT, TEXT, resume_path, "--resume", NULL, "FILE", WHAT("file name"), \
        "continue the render saved in FILE: only the\n" \
        "samples not in it are rendered, and the image is\n" \
        "the same bits as an uninterrupted render's. The\n" \
        "scene and settings must be the ones it was made\n" \
        "with (else exit status 3), but --spp may be\n" \
        "larger: samples are added to a finished render.\n" \
        "Checkpoints go on into FILE unless --checkpoint\n" \
        "names another file") \
    X(CHECKPOINT, CUSTOM, range_first, "--sample-range", NULL, "A:B", PARSE(parse_sample_range), \
        "render only samples A..B-1 of every pixel: a part\n" \
        "of the render for 'clpt merge' (with --checkpoint\n" \
        "PART); -o gets the part's own image") \
    X(MPI, SWITCH, mpi_broadcast, "--mpi-broadcast", NULL, NULL, NONE, \
        "rank 0 reads the scene and sends it to the\n" \
        "others (default: every rank reads SCENE, which\n" \
        "must then be on a shared path)") \
    X(MPI, SECONDS, mpi_timeout, "--mpi-timeout", NULL, "SECONDS", NONE, \
        "give a rank up after this long without a word\n" \
        "from it (default 30); its batches go to others.\n" \
        "Also how long the job may take to start") \
    X(SCENE, CHOICE, format, "--format", NULL, NULL, \
        ONE_OF({ "auto", SCENE_FORMAT_AUTO }, { "clpt", SCENE_FORMAT_CLPT }, { "classic", SCENE_FORMAT_CLASSIC }, \
               { "pbrt", SCENE_FORMAT_PBRT }), \
        "scene file format; default: told from the content\n" \
        "(pbrt: pbrt-v4 scenes, see docs/pbrt.md)") \
    X(SCENE, TEXT, camera, "--camera", NULL, "N|NAME", WHAT("camera index or name"), \
        "glTF: look through camera N (from 0) or the camera\n" \
        "(or camera node) named NAME; default: the first") \
    X(SCENE, CHOICE, integrator, "--integrator", NULL, NULL, \
        ONE_OF({ "path", INTEGRATOR_PATH }, { "whitted", INTEGRATOR_WHITTED }), \
        "path tracing (default) or the classic ray tracer\n" \
        "(the default for classic scenes): Phong shading,\n" \
        "hard shadows (see --shadows), mirror and\n" \
        "refraction rays up to --max-depth; one ray\n" \
        "through each pixel centre unless --spp N\n" \
        "(jittered; an m x m grid when N = m*m)") \
    X(SCENE, CHOICE, shadows, "--shadows", NULL, NULL, ONE_OF({ "on", 1 }, { "off", 0 }), \
        "whether lights can be blocked (shadow rays), in\n" \
        "both integrators; default: on, off for classic\n" \
        "scenes (as the course ray casters)") \
    X(SCENE, CUSTOM, n_sets, "--set", NULL, "KEY=VALUE", PARSE(parse_set), \
        "set a scene parameter by path once the scene is\n" \
        "read: camera.fov=30, image.spp=16,\n" \
        "material.red.albedo=0.8,0.2,0.2,\n" \
        "light.0.intensity=5 (repeatable; docs/\n" \
        "scene-format.md, \"Parameters by path\"); --spp\n" \
        "and the like still win") \
    X(SCENE, CUSTOM, adaptive, "--adaptive", NULL, "THRESHOLD", PARSE(parse_adaptive), \
        "whitted: after the first pass, render\n" \
        "--adaptive-spp more samples in each pixel that\n" \
        "differs from a neighbour by more than THRESHOLD\n" \
        "(0..1) in some channel") \
    X(SCENE, UINT, adaptive_spp, "--adaptive-spp", NULL, "N", RANGE(1, 65536), \
        "extra samples per such pixel (default 16; needs\n" \
        "--adaptive)") \
    X(VIEWER, SWITCH, interactive, "--interactive", "-i", NULL, NONE, \
        "show SCENE in a window and render it\n" \
        "progressively while the camera moves (needs a\n" \
        "display: else exit status 5). Keys: W/A/S/D\n" \
        "move, R/F or Q/E up/down, drag the mouse to\n" \
        "look, wheel forward/back, Z/X field of view,\n" \
        "Up/Down focus distance, Right/Left aperture,\n" \
        "+/- exposure, V view, Space pause, C save the image\n" \
        "(SCENE-view-NNN.png and .pfm, never over an\n" \
        "earlier save), P print the camera as a scene\n" \
        "block, H help, F11 full screen, Esc quit.\n" \
        "A view renders up to --spp (else the scene's\n" \
        "spp) samples per pixel") \
    X(DEVICES, SWITCH, list_devices, "--list-devices", NULL, NULL, NONE, \
        "print every OpenCL platform and device with its\n" \
        "index, and the scalar device, then exit") \
    X(DEVICES, TEXT, device_spec, "--device", NULL, "SPEC", WHAT("device list"), \
        "devices to render with, comma-separated: an\n" \
        "OpenCL device's index from --list-devices,\n" \
        "'all', 'gpu', 'cpu' (OpenCL CPU devices),\n" \
        "'scalar', or part of a device or platform\n" \
        "name. Default: every OpenCL GPU, else the\n" \
        "OpenCL CPU devices, else the scalar device") \
    X(DEVICES, INT, threads, "--threads", NULL, "N", RANGE(1, 256), \
        "worker threads of the scalar device (default:\n" \
        "all cores)") \
    X(REPORTING, SWITCH, stats, "--stats", NULL, NULL, ONE_OF({ "text", STATS_TEXT }, { "json", STATS_JSON }), \
        "print scene, tree (BVH or kd-tree), kernel\n" \
        "build, OpenCL wave (size, how it runs) and\n" \
        "per-device statistics to stdout; =json: one\n" \
        "JSON object at the end instead, for scripts\n" \
        "(docs/cli.md). To stderr when -o - writes the\n" \
        "image to stdout") \
    X(REPORTING, SWITCH, profile, "--profile", NULL, NULL, NONE, \
        "--stats, and where each device's time goes: ray\n" \
        "generation, traversal, shading, shadow rays,\n" \
        "film, queues, host waits (slows rendering)") \
    X(REPORTING, SWITCH, quiet, "--quiet", "-q", NULL, NONE, \
        "no progress bar and no summary line") \
    X(REPORTING, SWITCH, help, "--help", "-h", NULL, NONE, \
        "print this help and exit") \
    X(REPORTING, SWITCH, version, "--version", NULL, NULL, NONE, \
        "print the version and exit") \
    X(DEVELOPER, TEXT, kernel_dir, "--kernel-dir", NULL, "DIR", WHAT("folder name"), \
        "compile the kernels from DIR/entry.cl instead of\n" \
        "the copy built into the program (no kernel cache)") \
    X(DEVELOPER, UINT, batch, "--batch", NULL, "N", RANGE(1, 1000000), \
        "fixed batch size in samples per pixel (default:\n" \
        "adaptive, about 0.25 s of work per batch)") \
    X(DEVELOPER, UINT, wave_paths, "--wave-paths", NULL, "N", RANGE(1, 1L << 26), \
        "paths per OpenCL wave (default: 2^22 on GPUs of\n" \
        "8 GiB or more when it fits in half their\n" \
        "memory, else 2^20; on CPUs 2^16 per compute\n" \
        "unit up to 2^21 where it fits in half\n" \
        "the memory, else 2^16; 2^14 with\n" \
        "--interactive)") \
    X(DEVELOPER, CHOICE, wave_launch, "--wave-launch", NULL, NULL, \
        ONE_OF({ "counted", WAVE_LAUNCH_COUNTED }, { "bounded", WAVE_LAUNCH_BOUNDED }, \
               { "megakernel", WAVE_LAUNCH_MEGAKERNEL }), \
        "how an OpenCL device runs a wave: 'counted'\n" \
        "launches each bounce over the live paths the\n" \
        "device counted, read back first; 'bounded' all\n" \
        "bounces at once over the wave's size, the kernels\n" \
        "stopping at the count on the device (GPUs'\n" \
        "default); 'megakernel' one kernel that runs each\n" \
        "path to its end (CPUs' default; counted with\n" \
        "--profile)")

/* --help: each section's text, then its flags (a blank line after them). */
enum {
    HELP_INTRO, HELP_OUTPUT, HELP_CHECKPOINT, HELP_MPI, HELP_SCENE, HELP_VIEWER, HELP_DEVICES,
    HELP_REPORTING, HELP_DEVELOPER, HELP_END, HELP_SECTIONS
};

static const char *const help_sections[HELP_SECTIONS] = {
    [HELP_INTRO] =
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
"\n"
"Options and the scene come in any order; '--' ends the options. A flag's value\n"
"may follow it or an '=' (--spp=64); one-letter flags bundle (-qo out.png).\n"
"See docs/cli.md.\n"
"\n",
    [HELP_OUTPUT] = "Output and image:\n",
    [HELP_CHECKPOINT] = "Checkpoints (docs/checkpoint.md):\n",
    [HELP_MPI] =
"Merging parts (docs/distributed.md):\n"
"  clpt merge -o OUT PART...  add the films of --sample-range parts of one\n"
"                             render exactly: OUT is the same bits as one\n"
"                             process rendering every sample. Parts that\n"
"                             overlap, leave samples out or belong to other\n"
"                             renders are refused (exit status 3); parts of\n"
"                             a render whose --spp grew are one render. Also\n"
"                             --checkpoint FILE, --gamma srgb|none, -q,\n"
"                             --view and --exposure as a render's\n"
"\n"
"MPI (mpirun -np N clpt SCENE ..., or srun; docs/distributed.md):\n"
"                             one image from N processes, each on its own\n"
"                             devices (--device applies to each); rank 0\n"
"                             hands out batches, writes every output and\n"
"                             prints; the image is the same bits as one\n"
"                             process's. Not with --adaptive or --aov\n",
    [HELP_SCENE] = "Scene and integrator:\n",
    [HELP_VIEWER] = "Interactive viewer (docs/viewer.md):\n",
    [HELP_DEVICES] = "Devices:\n",
    [HELP_REPORTING] = "Reporting:\n",
    [HELP_DEVELOPER] = "Developer options:\n",
    [HELP_END] =
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
};

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

/* "normal,depth" -> the bits 1 << INTEGRATOR_AOV_NORMAL | 1 << INTEGRATOR_AOV_DEPTH */
static Status parse_aovs(const char *list, Options *o, Error *err)
{
    const char *p = list;
    do {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        unsigned found = 0;
        for (unsigned a = INTEGRATOR_AOV_NORMAL; a <= INTEGRATOR_AOV_ALBEDO; a++) {
            const char *name = passes_aov_name(a);
            if (strlen(name) == len && strncmp(p, name, len) == 0) found = a;
        }
        if (!found)
            return error_set(err, ST_USAGE, "--aov expects a comma-separated list of normal, depth, "
                             "albedo; got '%s'", list);
        o->aovs |= 1u << found;
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

/* --exposure EV: stops, as Blender's (-32..32) */
static Status parse_exposure(const char *v, Options *o, Error *err)
{
    char *end;
    errno = 0;
    double ev = strtod(v, &end);
    if (!*v || *end || errno || starts_blank(v) || !(ev >= -32.0 && ev <= 32.0))
        return error_set(err, ST_USAGE, "--exposure expects a number of stops from -32 to 32, got '%s'", v);
    o->exposure = ev;
    return ST_OK;
}

/* --set KEY=VALUE: kept as given, checked against the scene once it is read */
static Status parse_set(const char *v, Options *o, Error *err)
{
    const char *eq = strchr(v, '=');
    if (!eq || eq == v)
        return error_set(err, ST_USAGE, "--set expects KEY=VALUE (camera.fov=30, material.NAME.albedo=0.8,0.2,0.2), "
                         "got '%s'", v);
    if (o->n_sets == OPTIONS_MAX_SETS) return error_set(err, ST_USAGE, "more than %d --set", OPTIONS_MAX_SETS);
    o->sets[o->n_sets++] = v;
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

/* ---------------------------------------------------------------- the table */

#define NONE .what = NULL
#define WHAT(text) .what = (text)
#define RANGE(low, high) .lo = (low), .hi = (high)
#define ONE_OF(...) .choices = (const OptionChoice[]){ __VA_ARGS__, { NULL, 0 } }
#define PARSE(function) .parse = (function)

static const OptionSpec option_specs[] = {
#define X(sec, kind, field, name, alias, metavar, extra, text) \
    { name, alias, OPTION_##kind, metavar, offsetof(Options, field), extra, .section = HELP_##sec, .help = text },
    OPTIONS(X)
#undef X
};

/* Each field has the type its kind stores. */
#define FITS_SWITCH(e) _Generic((e), int: 1, default: 0)
#define FITS_TEXT(e) _Generic((e), const char *: 1, default: 0)
#define FITS_LONG(e) _Generic((e), long: 1, default: 0)
#define FITS_UINT(e) _Generic((e), unsigned: 1, default: 0)
#define FITS_INT(e) _Generic((e), int: 1, default: 0)
#define FITS_SECONDS(e) _Generic((e), double: 1, default: 0)
#define FITS_CHOICE(e) _Generic((e), int: 1, default: 0)
#define FITS_CUSTOM(e) 1
#define X(section, kind, field, name, alias, metavar, extra, help) \
    _Static_assert(FITS_##kind(((Options *)0)->field), name ": Options." #field " is not what OPTION_" #kind " sets");
OPTIONS(X)
#undef X

#define N_OPTIONS (sizeof option_specs / sizeof option_specs[0])

const OptionSpec *options_flag(size_t i)
{
    return i < N_OPTIONS ? &option_specs[i] : NULL;
}

/* A choice's words joined by `sep`, or written for a message ("'a', 'b' or 'c'"). */
static void choices_text(const OptionChoice *c, int quoted, char *buf, size_t size)
{
    size_t len = 0, n = 0;
    while (c[n].name) n++;
    buf[0] = '\0';
    for (size_t i = 0; i < n && len < size; i++) {
        const char *sep = i == 0 ? "" : !quoted ? "|" : i + 1 == n ? " or " : ", ";
        int w = snprintf(buf + len, size - len, quoted ? "%s'%s'" : "%s%s", sep, c[i].name);
        if (w < 0) break;
        len += (size_t)w;
    }
}

/* What follows a flag's name in --help and the man page: " FILE", " bvh|kdtree", or
 * "[=text|json]" for a switch that may take a word; "" for a plain switch. */
void option_value_text(const OptionSpec *s, char *buf, size_t size)
{
    char words[96];
    if (s->choices) choices_text(s->choices, 0, words, sizeof words);
    else snprintf(words, sizeof words, "%s", s->metavar ? s->metavar : "");
    if (s->kind == OPTION_SWITCH) snprintf(buf, size, s->choices ? "[=%s]" : "", words);
    else snprintf(buf, size, " %s", words);
}

/* "  -o, --output FILE", then the help from column 29 (on a line of its own when the
 * flag is longer). */
static void print_flag(FILE *f, const OptionSpec *s)
{
    char value[96];
    option_value_text(s, value, sizeof value);
    char label[160];
    int n = snprintf(label, sizeof label, "  %s%s%s%s", s->alias ? s->alias : "  ", s->alias ? ", " : "  ",
                     s->name, value);
    enum { HELP_COLUMN = 29 };
    if (n < HELP_COLUMN) fprintf(f, "%-*s", HELP_COLUMN, label);
    else fprintf(f, "%s\n%*s", label, HELP_COLUMN, "");
    for (const char *p = s->help; *p; p++) {
        fputc(*p, f);
        if (*p == '\n') fprintf(f, "%*s", HELP_COLUMN, "");
    }
    fputc('\n', f);
}

size_t options_help_sections(void)
{
    return HELP_SECTIONS;
}

const char *options_help_section(size_t i)
{
    return i < HELP_SECTIONS ? help_sections[i] : NULL;
}

void options_print_help(FILE *f)
{
    for (int sec = 0; sec < HELP_SECTIONS; sec++) {
        fputs(help_sections[sec], f);
        int any = 0;
        for (size_t k = 0; k < N_OPTIONS; k++)
            if (option_specs[k].section == sec) {
                print_flag(f, &option_specs[k]);
                any = 1;
            }
        if (any) fputc('\n', f);
    }
}

/* ---------------------------------------------------------------- parsing */

/* The flag named `a` (its name or alias); NULL: none. */
static const OptionSpec *option_find(const char *a)
{
    for (size_t k = 0; k < N_OPTIONS; k++) {
        const OptionSpec *s = &option_specs[k];
        if (strcmp(a, s->name) == 0 || (s->alias && strcmp(a, s->alias) == 0)) return s;
    }
    return NULL;
}

/* Levenshtein distance between two short words (a flag as typed and a listed one);
 * words past 63 characters are as far as can be. */
static size_t edit_distance(const char *a, const char *b)
{
    enum { MAX = 64 };
    size_t la = strlen(a), lb = strlen(b), row[MAX];
    if (la >= MAX || lb >= MAX) return (size_t)-1;
    for (size_t j = 0; j <= lb; j++) row[j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t up = row[j];
            size_t best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best) best = up + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb];
}

/* The listed flag a mistyped `a` most likely meant: the nearest name, when it is at
 * most two edits away and those edits are fewer than half of what was typed (so that
 * "-x" suggests nothing); NULL: none is near. */
static const char *option_nearest(const char *a)
{
    const char *best = NULL;
    size_t best_d = 3, letters = strspn(a, "-") < strlen(a) ? strlen(a) - strspn(a, "-") : 0;
    for (size_t k = 0; k < N_OPTIONS; k++) {
        size_t d = edit_distance(a, option_specs[k].name);
        if (d < best_d && 2 * d < letters + 1) {
            best_d = d;
            best = option_specs[k].name;
        }
    }
    return best;
}

/* "unknown option '--sp'; did you mean '--spp'?" (main adds the one hint at --help). */
static Status option_unknown(const char *a, Error *err)
{
    const char *near = option_nearest(a);
    if (near) return error_set(err, ST_USAGE, "unknown option '%s'; did you mean '%s'?", a, near);
    return error_set(err, ST_USAGE, "unknown option '%s'", a);
}

/* One of a CHOICE flag's words (or of a SWITCH's after '=') into the int at dst. */
static Status option_set_choice(const OptionSpec *s, const char *a, const char *v, void *dst, Error *err)
{
    for (const OptionChoice *c = s->choices; c->name; c++)
        if (strcmp(v, c->name) == 0) {
            *(int *)dst = c->value;
            return ST_OK;
        }
    char expected[160];
    choices_text(s->choices, 1, expected, sizeof expected);
    return error_set(err, ST_USAGE, "%s expects %s, got '%s'", a, expected, v);
}

/* Reads v, the value of flag `a` (as typed; NULL for a switch given alone), into its
 * field of o. */
static Status option_set(const OptionSpec *s, const char *a, const char *v, Options *o, Error *err)
{
    void *dst = (char *)o + s->offset;
    long n = 0;
    Status st = ST_OK;
    switch (s->kind) {
    case OPTION_SWITCH:
        if (!v) {
            *(int *)dst = 1;
            return ST_OK;
        }
        if (!s->choices) return error_set(err, ST_USAGE, "%s takes no value, got '%s=%s'", a, a, v);
        return option_set_choice(s, a, v, dst, err);
    case OPTION_TEXT:
        if (!*v) return error_set(err, ST_USAGE, "%s needs a %s", a, s->what);
        *(const char **)dst = v;
        return ST_OK;
    case OPTION_LONG: return parse_long(a, v, s->lo, s->hi, (long *)dst, err);
    case OPTION_UINT:
        if (!(st = parse_long(a, v, s->lo, s->hi, &n, err))) *(unsigned *)dst = (unsigned)n;
        return st;
    case OPTION_INT:
        if (!(st = parse_long(a, v, s->lo, s->hi, &n, err))) *(int *)dst = (int)n;
        return st;
    case OPTION_SECONDS: return parse_seconds(a, v, (double *)dst, err);
    case OPTION_CHOICE: return option_set_choice(s, a, v, dst, err);
    case OPTION_CUSTOM: return s->parse(v, o, err);
    }
    return error_set(err, ST_INTERNAL, "%s: unknown kind of flag", a);
}

/* A switch given a value (the library's settings): on or off. */
static Status option_switch_value(const char *name, const char *v, int *dst, Error *err)
{
    static const char *const on[] = { "1", "on", "true", "yes" }, *const off[] = { "0", "off", "false", "no" };
    for (size_t i = 0; i < 4; i++)
        if (strcmp(v, on[i]) == 0 || strcmp(v, off[i]) == 0) {
            *dst = strcmp(v, on[i]) == 0;
            return ST_OK;
        }
    return error_set(err, ST_USAGE, "%s is a switch: expects 1, on, true or 0, off, false, got '%s'", name, v);
}

Status options_set(Options *o, const char *name, const char *value, Error *err)
{
    char flag[64];
    if (!name || !value) return error_set(err, ST_USAGE, "an option needs a name and a value");
    if (strncmp(name, "--", 2) == 0) name += 2;
    if (strlen(name) + 3 > sizeof flag) return error_set(err, ST_USAGE, "unknown option '%s'", name);
    snprintf(flag, sizeof flag, "--%s", name);
    const OptionSpec *s = option_find(flag);
    if (!s) return error_set(err, ST_USAGE, "unknown option '%s'", name);
    /* a switch with choices (--stats=json) also takes one of them by name */
    if (s->kind == OPTION_SWITCH && (!s->choices || option_switch_value(flag, value, &(int){ 0 }, NULL) == ST_OK))
        return option_switch_value(flag, value, (int *)((char *)o + s->offset), err);
    return option_set(s, flag, value, o, err);
}

void options_init(Options *o)
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

/* The one scene argument. */
static Status options_scene(const char *a, Options *o, Error *err)
{
    if (o->scene_path)
        return error_set(err, ST_USAGE, "more than one scene given: '%s' and '%s'", o->scene_path, a);
    o->scene_path = a;
    return ST_OK;
}

/* The value of flag `a` that takes one: `value` (after '=' or in the same word), else
 * the next argument (advancing *i). */
static Status option_take_value(const OptionSpec *s, const char *a, const char *value, int argc, char **argv, int *i,
                                Options *o, Error *err)
{
    if (!value && *i + 1 >= argc) return error_set(err, ST_USAGE, "%s needs a value", a);
    if (!value) value = argv[++*i];
    return option_set(s, a, value, o, err);
}

/* -qo FILE: one-letter flags bundled in one word, as getopt reads them. Switches may
 * follow each other; a flag that takes a value ends the bundle, its value the rest of
 * the word (-ofile.png) or the next argument. */
static Status options_parse_bundle(int argc, char **argv, int *i, Options *o, Error *err)
{
    const char *a = argv[*i];
    for (const char *p = a + 1; *p; p++) {
        char one[3] = { '-', *p, '\0' };
        const OptionSpec *s = option_find(one);
        if (!s && p == a + 1) return option_unknown(a, err);   /* not a bundle: "-spp" */
        if (!s) return error_set(err, ST_USAGE, "unknown option '%s' in '%s'", one, a);
        if (s->kind != OPTION_SWITCH) return option_take_value(s, one, p[1] ? p + 1 : NULL, argc, argv, i, o, err);
        Status st = option_set(s, one, NULL, o, err);
        if (st) return st;
    }
    return ST_OK;
}

/* argv[*i]: a flag (with its value, advancing *i past it), a bundle of short flags,
 * "--" (after which every argument is the scene's: *ended), or the scene. */
static Status options_parse_arg(int argc, char **argv, int *i, int *ended, Options *o, Error *err)
{
    const char *a = argv[*i];
    if (*ended || a[0] != '-' || a[1] == '\0') return options_scene(a, o, err);
    if (strcmp(a, "--") == 0) {
        *ended = 1;
        return ST_OK;
    }
    if (a[1] != '-' && a[2] != '\0') return options_parse_bundle(argc, argv, i, o, err);
    /* --flag=value is accepted too */
    char flag[64];
    const char *value = NULL;
    const char *eq = a[1] == '-' ? strchr(a, '=') : NULL;
    if (eq) {
        size_t n = (size_t)(eq - a);
        if (n >= sizeof flag) return option_unknown(a, err);
        memcpy(flag, a, n);
        flag[n] = '\0';
        value = eq + 1;
        a = flag;
    }
    const OptionSpec *s = option_find(a);
    if (!s) return option_unknown(a, err);
    if (s->kind == OPTION_SWITCH) return option_set(s, a, value, o, err);
    return option_take_value(s, a, value, argc, argv, i, o, err);
}

/* The viewer writes no output file of its own (C saves frames) and renders until it is
 * closed: the flags that shape a batch render's files and its end do not apply. */
static Status options_check_interactive(const Options *o, Error *err)
{
    if (!o->interactive) return ST_OK;
    const char *flag = o->output ? "--output" : o->checkpoint_path ? (o->resume_path ? "--resume" : "--checkpoint")
                     : o->time_limit > 0.0 ? "--time-limit" : o->progressive_seconds > 0.0 ? "--progressive-output"
                     : o->aovs ? "--aov" : o->adaptive > 0.0 ? "--adaptive"
                     : o->range_end >= 0 ? "--sample-range" : o->stats == STATS_JSON ? "--stats=json" : NULL;
    if (flag)
        return error_set(err, ST_USAGE, "--interactive cannot be combined with %s (the viewer saves frames "
                                        "with the C key; see docs/viewer.md)", flag);
    return ST_OK;
}

/* -o - (or FORMAT:-) writes the image to standard output once, at the end: the flags
 * that write it again, or write images beside it, need a file. */
static Status options_check_stdout(const Options *o, Error *err)
{
    if (!o->output || !image_path_is_stdout(o->output)) return ST_OK;
    const char *flag = o->progressive_seconds > 0.0 ? "--progressive-output" : o->aovs ? "--aov"
                     : o->adaptive > 0.0 ? "--adaptive" : NULL;
    if (flag)
        return error_set(err, ST_USAGE, "%s cannot be used with -o %s: standard output takes the image once, "
                         "and %s writes it again or beside it; name a file with -o", flag, o->output, flag);
    return ST_OK;
}

/* What depends on several flags. */
Status options_finish(Options *o, Error *err)
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
        return error_set(err, ST_USAGE, "no scene given (usage: clpt [options] SCENE)");
    Status st = options_check_stdout(o, err);
    return st ? st : options_check_interactive(o, err);
}

Status options_parse(int argc, char **argv, Options *o, Error *err)
{
    options_init(o);
    int first = 1;
    CourseStyle course = course_args_style(argc, argv);
    if (course != COURSE_NONE) {
        Status st = course_args_parse(course, argc, argv, o, &first, err);
        if (st) return st;
    }
    int ended = 0;
    for (int i = first; i < argc; i++) {
        Status st = options_parse_arg(argc, argv, &i, &ended, o, err);
        if (st) return st;
    }
    return options_finish(o, err);
}
