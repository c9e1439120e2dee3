/* options.c — the command line's flags: OPTIONS(X) below is THE list of them (as
 * kernels/scene_buffers.h is of the scene buffers). The table the parser reads
 * (options_parse.c), the flag lines of --help and the man page, and the choices an
 * error message lists are all generated from it, with the value parsers that flags of
 * their own kind need. A new flag is one entry there (and its field in Options,
 * option_values.h). */
#include "options.h"

#include "course_args.h"

#include "device/device.h"
#include "io/image_write.h"
#include "io/scene_load.h"
#include "io/view_transform.h"
#include "render/display.h"
#include "render/adaptive.h"
#include "render/passes.h"
#include "scene/crop.h"
#include "base/limit.h"
#include "types.h"

#include <ctype.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* --frames' largest frame number: names keep four digits at least (OUT_0042.png), and
 * a million frames is some eleven hours of film at 24 fps */
#define CLPT_MAX_FRAME 999999

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
        "image to write: .png, .jpg/.jpeg, .ppm or .bmp\n" \
        "(8-bit sRGB; --png-depth 16, --jpeg-quality)\n" \
        "or .pfm, .exr (half; see --exr-float) or .hdr\n" \
        "(linear float); default: the file a pbrt\n" \
        "scene's Film names, else SCENE's name\n" \
        "with .png, in the current folder. Written\n" \
        "atomically; a symlink is followed and an\n" \
        "existing file keeps its permissions; only a\n" \
        "regular file is replaced (a FIFO or device\n" \
        "is refused). Checked before rendering.\n" \
        "'-' writes PNG to standard output, FORMAT:-\n" \
        "(jpg:-, exr:-, pfm:-, ppm:-, bmp:-, hdr:-) that\n" \
        "format") \
    X(OUTPUT, LONG, spp, "--spp", NULL, "N", RANGE(1, CLPT_MAX_SPP), \
        "samples per pixel (overrides the scene)") \
    X(OUTPUT, LONG, width, "--width", NULL, "N", RANGE(1, CLPT_MAX_IMAGE_SIDE), \
        "image width in pixels (overrides the scene)") \
    X(OUTPUT, LONG, height, "--height", NULL, "N", RANGE(1, CLPT_MAX_IMAGE_SIDE), \
        "image height in pixels (overrides the scene)") \
    X(OUTPUT, CUSTOM, crop_kind, "--crop", NULL, "X0,X1,Y0,Y1", PARSE(parse_crop), \
        "render only this window of the image, in\n" \
        "fractions of its width and height (0 <= X0 <\n" \
        "X1 <= 1, 0 <= Y0 < Y1 <= 1, rows from the top;\n" \
        "pbrt's cropwindow): the output is the window,\n" \
        "its pixels the same bits as the whole render's") \
    X(OUTPUT, CUSTOM, crop_kind, "--pixel-bounds", NULL, "X0,X1,Y0,Y1", PARSE(parse_pixel_bounds), \
        "render only pixel columns X0..X1-1 and rows\n" \
        "Y0..Y1-1 (row 0 at the top; pbrt's\n" \
        "pixelbounds): the output is that window, as\n" \
        "with --crop") \
    X(OUTPUT, LONG, seed, "--seed", NULL, "N", RANGE(0, 4294967295L), \
        "random seed; the same seed gives the same image\n" \
        "on any devices and batch sizes") \
    X(OUTPUT, LONG, max_depth, "--max-depth", NULL, "N", RANGE(0, CLPT_MAX_DEPTH), \
        "longest path, in bounces (overrides the scene)") \
    X(OUTPUT, CUSTOM, split, "--split", NULL, "N|auto", PARSE(parse_split), \
        "path tracer: shade each camera sample's first hit\n" \
        "N times, each with its own light sample and\n" \
        "continuation weighted 1/N, sharing the camera ray\n" \
        "(1..64; 1: none; overrides the scene's image\n" \
        "split). auto, the default: a short pilot render\n" \
        "of a sparse grid of pixels measures 1, 2, 4 and\n" \
        "16, and the render takes the one of 1, 2, 4, 8, 16\n" \
        "of least error x rays on the curve fitted to\n" \
        "them, the same on any devices; small renders\n" \
        "keep 1 (docs/design.md, First-hit splitting)") \
    X(OUTPUT, CUSTOM, noise_threshold, "--noise-threshold", NULL, "T", PARSE(parse_noise_threshold), \
        "path tracer: adaptive sampling; a pixel stops once\n" \
        "its estimated error is below T (0..1; 0.01 clean,\n" \
        "0.1 quick; docs/adaptive.md), --spp is the most\n" \
        "any pixel gets") \
    X(OUTPUT, UINT, min_spp, "--min-spp", NULL, "N", RANGE(2, CLPT_MAX_SPP), \
        "samples of every pixel before --noise-threshold\n" \
        "stops any (default 16)") \
    X(OUTPUT, CUSTOM, clamp, "--clamp", NULL, "V", PARSE(parse_clamp), \
        "path tracer: no channel of a sample's indirect\n" \
        "light (after the first bounce) passes V; takes\n" \
        "out fireflies but is biased (darker); default:\n" \
        "off (docs/adaptive.md, \"Clamping\")") \
    X(OUTPUT, CHOICE, sampler, "--sampler", NULL, NULL, \
        ONE_OF({ "sobol", SAMPLER_SOBOL }, { "independent", SAMPLER_INDEPENDENT }), \
        "random numbers: Owen-scrambled Sobol points\n" \
        "(default; less noise) or independent ones\n" \
        "(clpt's earlier sampler, the same images)") \
    X(OUTPUT, CHOICE, accel, "--accel", NULL, NULL, ONE_OF({ "bvh", ACCEL_BVH }, { "kdtree", ACCEL_KDTREE }), \
        "the tree rays find primitives through: an 8-wide\n" \
        "BVH (default; faster) or the SAH kd-tree (with\n" \
        "instances: a kd-tree per object under the BVH's\n" \
        "top level)") \
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
    X(OUTPUT, SWITCH, denoise, "--denoise", NULL, NULL, NONE, \
        "denoise the finished image with Intel Open\n" \
        "Image Denoise (its RT filter, with albedo and\n" \
        "normal images rendered at the image's spp,\n" \
        "through mirrors and clear glass);\n" \
        "an .exr output also keeps the noisy colour\n" \
        "(noisy.R/G/B), the features and the emission\n" \
        "left out and added back (emission.R/G/B,\n" \
        "emission4x.R/G/B) as channels. With\n" \
        "--sample-range and --checkpoint PART: PART\n" \
        "keeps the denoiser's inputs for merge --denoise.\n" \
        "Needs OIDN: sh tools/deps.sh oidn\n" \
        "(docs/denoise.md)") \
    X(OUTPUT, CUSTOM, display_server, "--display-server", NULL, "HOST:PORT", PARSE(parse_display_server), \
        "show the image in the tev viewer listening at\n" \
        "HOST:PORT as it converges (once a second, and\n" \
        "the final image); a server that cannot be\n" \
        "reached or goes away is a warning, and the\n" \
        "render goes on (docs/display-server.md)") \
    X(OUTPUT, UINT, jpeg_quality, "--jpeg-quality", NULL, "Q", RANGE(1, 100), \
        "quality of a JPEG output, 1..100 (default 90)") \
    X(OUTPUT, CHOICE, png_depth, "--png-depth", NULL, NULL, ONE_OF({ "8", 8 }, { "16", 16 }), \
        "bits per channel of a PNG output (default 8)") \
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
    X(OUTPUT, CUSTOM, frames_first, "--frames", NULL, "A:B", PARSE(parse_frames), \
        "render frames A to B (both included) of a glTF\n" \
        "file's animation or a scene's camera_path,\n" \
        "frame k at k/FPS seconds, each to its own\n" \
        "numbered image: -o out.png gives out_0000.png\n" \
        "...; frames already written are skipped\n" \
        "(docs/animation.md)") \
    X(OUTPUT, CUSTOM, fps, "--fps", NULL, "FPS", PARSE(parse_fps), \
        "frames per second of animation time for\n" \
        "--frames (default 24)") \
    X(OUTPUT, CUSTOM, anim_time, "--time", NULL, "T", PARSE(parse_anim_time), \
        "render the pose of a glTF file's animation or a\n" \
        "scene's camera_path at T seconds (0 to its\n" \
        "end): one still image, as frame T*FPS of\n" \
        "--frames (docs/animation.md)") \
    X(OUTPUT, CUSTOM, shutter_open, "--shutter", NULL, "A:B|F", PARSE(parse_shutter), \
        "motion blur of a glTF file's animation: the\n" \
        "shutter open from A to B seconds (0 <= A < B),\n" \
        "moving meshes and the camera sampled over it;\n" \
        "with --frames, --shutter F: each frame open for\n" \
        "the fraction F of a frame's time (0 < F <= 1),\n" \
        "from the frame's time (docs/motion.md)") \
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
    X(SCENE, CUSTOM, lookat, "--lookat", NULL, "EYE,AT,UP", PARSE(parse_lookat), \
        "look from EYE at AT, UP upwards: nine numbers\n" \
        "EX,EY,EZ,AX,AY,AZ,UX,UY,UZ (--lookat\n" \
        "0,1,5,0,1,0,0,1,0); replaces the camera's frame\n" \
        "in every scene format, as --set camera.from=,\n" \
        "camera.at= and camera.up= do") \
    X(SCENE, CUSTOM, fov, "--fov", NULL, "DEGREES", PARSE(parse_fov), \
        "vertical field of view of a perspective camera,\n" \
        "in (0, 180) degrees (as --set camera.fov=)") \
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
        "+/- exposure, V view, N denoised view (on with\n" \
        "--denoise), Space pause, C save the image\n" \
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
"                             --view and --exposure as a render's, and\n"
"                             --denoise (as one process's --denoise when\n"
"                             the parts were rendered with --denoise and\n"
"                             hold its features; else the colour alone)\n"
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
"  CLPT_OIDN_DIR              the only folder --denoise loads Open Image\n"
"                             Denoise from (default: oidn/lib beside the\n"
"                             program, else the system's library path)\n"
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

/* The whole of `s` as one number (strtod's syntax, no blank at either end) into *out;
 * 0 unless exactly that. Every flag that takes one real number reads it here. */
static int read_real(const char *s, double *out)
{
    char *end;
    errno = 0;
    *out = strtod(s, &end);
    return *s && !*end && !errno && !starts_blank(s);
}

/* n numbers separated by commas, nothing else (no blanks: what was typed is what
 * counts), into out; 0 unless exactly that. */
static int read_number_list(const char *v, double *out, int n)
{
    const char *p = v;
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        out[i] = strtod(p, &end);
        if (end == p || errno || starts_blank(p) || !isfinite(out[i])) return 0;
        if (*end != (i + 1 < n ? ',' : '\0')) return 0;
        p = end + 1;
    }
    return 1;
}

/* "A:B", two whole numbers without a sign (no blanks), into *a and *b; 0 unless
 * exactly that. --sample-range and --frames read theirs here. */
static int read_index_pair(const char *s, long *a, long *b)
{
    char *end;
    errno = 0;
    *a = strtol(s, &end, 10);
    if (end == s || *end != ':' || errno || s[0] == '-' || s[0] == '+' || starts_blank(s)) return 0;
    const char *second = end + 1;
    *b = strtol(second, &end, 10);
    return end != second && !*end && !errno && second[0] != '-' && second[0] != '+' && !starts_blank(second);
}

Status option_parse_long(const char *flag, const char *s, long lo, long hi, long *out, Error *err)
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

Status option_parse_seconds(const char *flag, const char *s, double *out, Error *err)
{
    double v;
    if (!read_real(s, &v) || !isfinite(v) || v <= 0.0)
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

/* --display-server HOST:PORT, checked now; connected once the scene is read */
static Status parse_display_server(const char *v, Options *o, Error *err)
{
    Status st = display_check_address(v, err);
    if (st == ST_OK) o->display_server = v;
    return st;
}

/* --depth-range NEAR,FAR */
static Status parse_depth_range(const char *v, Options *o, Error *err)
{
    double d[2];
    /* NEAR > FAR turns the ramp round: --depth-range 18,8 is the courses' -depth 8 18
     * (near black, far white) */
    if (!read_number_list(v, d, 2) || !(d[0] >= 0.0) || !(d[1] >= 0.0) || !(d[1] != d[0]))
        return error_set(err, ST_USAGE, "--depth-range expects NEAR,FAR, two different distances >= 0 "
                         "(NEAR > FAR inverts the grey), got '%s'", v);
    o->depth_near = d[0];
    o->depth_far = d[1];
    return ST_OK;
}

/* --sample-range A:B, 0 <= A < B <= CLPT_MAX_SPP (B is checked against the render's
 * samples per pixel once the scene is read). */
static Status parse_sample_range(const char *v, Options *o, Error *err)
{
    long a, b;
    if (!read_index_pair(v, &a, &b) || a < 0 || b <= a || b > CLPT_MAX_SPP)
        return error_set(err, ST_USAGE, "--sample-range expects A:B, sample indices with 0 <= A < B <= %d, got '%s'",
                         CLPT_MAX_SPP, v);
    o->range_first = a;
    o->range_end = b;
    return ST_OK;
}

/* --frames A:B, 0 <= A <= B <= CLPT_MAX_FRAME (B is checked against the animation's
 * length once the scene is read). */
static Status parse_frames(const char *v, Options *o, Error *err)
{
    long a, b;
    if (!read_index_pair(v, &a, &b) || a < 0 || b > CLPT_MAX_FRAME)
        return error_set(err, ST_USAGE, "--frames expects A:B, frame numbers with 0 <= A <= B <= %d, got '%s'",
                         CLPT_MAX_FRAME, v);
    if (a > b)
        return error_set(err, ST_USAGE, "--frames %s: the first frame, %ld, is after the last, %ld", v, a, b);
    o->frames_first = a;
    o->frames_last = b;
    return ST_OK;
}

/* The window of --crop or --pixel-bounds (`kind`, enum CropKind); one of the two. */
static Status set_crop(unsigned kind, const char *v, const double a[4], Options *o, Error *err)
{
    if (o->crop_kind && o->crop_kind != kind)
        return error_set(err, ST_USAGE, "--crop and --pixel-bounds both choose the window to render: give one");
    o->crop_kind = kind;
    memcpy(o->crop, a, sizeof o->crop);
    o->crop_text = v;
    return ST_OK;
}

/* --crop X0,X1,Y0,Y1: fractions, 0 <= X0 < X1 <= 1 (pbrt's cropwindow); whether it
 * holds a pixel is known once the image's size is (scene_options.c). */
static Status parse_crop(const char *v, Options *o, Error *err)
{
    double a[4];
    if (!read_number_list(v, a, 4) || !(a[0] >= 0.0 && a[0] < a[1] && a[1] <= 1.0) ||
        !(a[2] >= 0.0 && a[2] < a[3] && a[3] <= 1.0))
        return error_set(err, ST_USAGE, "--crop expects X0,X1,Y0,Y1, fractions of the image with "
                         "0 <= X0 < X1 <= 1 and 0 <= Y0 < Y1 <= 1, got '%s'", v);
    return set_crop(CROP_FRACTIONS, v, a, o, err);
}

/* --pixel-bounds X0,X1,Y0,Y1: columns [X0, X1) and rows [Y0, Y1); within the image is
 * checked once its size is known (scene_options.c). */
static Status parse_pixel_bounds(const char *v, Options *o, Error *err)
{
    double a[4];
    int ok = read_number_list(v, a, 4);
    for (int i = 0; ok && i < 4; i++) ok = a[i] == floor(a[i]) && a[i] >= 0.0 && a[i] <= CLPT_MAX_IMAGE_SIDE;
    if (!ok || !(a[0] < a[1]) || !(a[2] < a[3]))
        return error_set(err, ST_USAGE, "--pixel-bounds expects X0,X1,Y0,Y1, whole pixels with 0 <= X0 < X1 "
                         "and 0 <= Y0 < Y1 (columns X0..X1-1, rows Y0..Y1-1), got '%s'", v);
    return set_crop(CROP_PIXELS, v, a, o, err);
}

/* The flags whose value is one real number in a range, into a double of Options: one
 * parser each, written by REAL_FLAG from the test on x and the message's front (", got
 * 'VALUE'" is added). */
#define REAL_FLAG(function, field, test, expects)                                       \
    static Status function(const char *v, Options *o, Error *err)                       \
    {                                                                                   \
        double x;                                                                       \
        if (!read_real(v, &x) || !(test)) return error_set(err, ST_USAGE, expects ", got '%s'", v); \
        o->field = x;                                                                   \
        return ST_OK;                                                                   \
    }
REAL_FLAG(parse_fps, fps, x > 0.0 && x <= 1000.0,
          "--fps expects a number of frames per second above 0 and at most 1000")
/* --shutter A:B: two finite times in seconds, 0 <= A < B (the animation's end is
 * checked once the scene is read) */
static Status parse_shutter(const char *v, Options *o, Error *err)
{
    const char *colon = strchr(v, ':');
    char first[64];
    double a, b;
    if (!colon) {
        /* F alone: a fraction of each frame's time, for --frames (checked there) */
        if (!read_real(v, &a) || !(a > 0.0 && a <= 1.0))
            return error_set(err, ST_USAGE, "--shutter expects A:B, the times in seconds it opens and closes, or with "
                             "--frames F, the fraction of each frame's time it is open (0 < F <= 1), got '%s'", v);
        o->shutter_fraction = a;
        return ST_OK;
    }
    size_t len = colon ? (size_t)(colon - v) : 0;
    if (colon && len < sizeof first) {
        memcpy(first, v, len);
        first[len] = '\0';
    }
    if (!colon || len >= sizeof first || !read_real(first, &a) || !read_real(colon + 1, &b) || !isfinite(a) ||
        !isfinite(b) || a < 0.0 || b < 0.0)
        return error_set(err, ST_USAGE, "--shutter expects A:B, the times in seconds it opens and closes (finite, "
                         "0 or more), got '%s'", v);
    if (!(b > a))
        return error_set(err, ST_USAGE, "--shutter %s: it closes at %g s, not after it opens at %g s (for one time, "
                         "--time)", v, b, a);
    o->shutter_open = a;
    o->shutter_close = b;
    return ST_OK;
}

/* --time T: seconds, 0 or more (the animation's end is checked once the scene is read) */
REAL_FLAG(parse_anim_time, anim_time, isfinite(x) && x >= 0.0,
          "--time expects a time in seconds, a finite number 0 or more")
/* --exposure EV: stops, as Blender's (-32..32) */
REAL_FLAG(parse_exposure, exposure, x >= -32.0 && x <= 32.0, "--exposure expects a number of stops from -32 to 32")
REAL_FLAG(parse_adaptive, adaptive, x > 0.0 && x <= 1.0, "--adaptive expects a threshold in (0, 1]")
REAL_FLAG(parse_noise_threshold, noise_threshold, x > 0.0 && x <= 1.0,
          "--noise-threshold expects a threshold in (0, 1]")
REAL_FLAG(parse_clamp, clamp, x > 0.0 && x <= 65536.0, "--clamp expects a radiance limit in (0, 65536]")
#undef REAL_FLAG

/* --split N|auto: a count in 1..CLPT_MAX_SPLIT, or auto (0, SCENE_SPLIT_AUTO) */
static Status parse_split(const char *v, Options *o, Error *err)
{
    double x;
    if (strcmp(v, "auto") == 0) {
        o->split = 0;
        return ST_OK;
    }
    if (!read_real(v, &x) || x != floor(x) || x < 1.0 || x > CLPT_MAX_SPLIT)
        return error_set(err, ST_USAGE, "--split expects auto or an integer in 1..%d, got '%s'", CLPT_MAX_SPLIT, v);
    o->split = (long)x;
    return ST_OK;
}

/* --lookat EX,EY,EZ,AX,AY,AZ,UX,UY,UZ: the eye, the point looked at and the up
 * direction. They need nothing of the scene, so the frame is checked here as a whole,
 * as the scene readers check a camera block: distinct points, an up direction that is
 * neither zero nor along the view. Every number must fit a float, as the camera's. */
static Status parse_lookat(const char *v, Options *o, Error *err)
{
    double a[9];
    int ok = read_number_list(v, a, 9);
    for (int i = 0; ok && i < 9; i++) ok = fabs(a[i]) <= FLT_MAX;
    if (!ok)
        return error_set(err, ST_USAGE, "--lookat expects EX,EY,EZ,AX,AY,AZ,UX,UY,UZ, nine numbers: the eye, the "
                         "point looked at and the up direction, got '%s'", v);
    double d[3] = { a[3] - a[0], a[4] - a[1], a[5] - a[2] }, *u = a + 6;
    double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    double c[3] = { d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0] };
    if (!(dl > 0.0))
        return error_set(err, ST_USAGE, "--lookat %s: the eye and the point looked at are the same point", v);
    if (!(ul > 0.0)) return error_set(err, ST_USAGE, "--lookat %s: the up direction is 0,0,0", v);
    /* the sine of the angle between up and the view, as the scene reader's test */
    if (!(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) > 1e-6 * dl * ul))
        return error_set(err, ST_USAGE, "--lookat %s: the up direction is parallel to the view direction (from the "
                         "eye to the point looked at)", v);
    o->lookat = v;
    return ST_OK;
}

/* --fov DEGREES: in (0, 180), as a camera block's fov */
static Status parse_fov(const char *v, Options *o, Error *err)
{
    double f;
    if (!read_real(v, &f) || !(f > 0.0 && f < 180.0))
        return error_set(err, ST_USAGE, "--fov expects a vertical field of view in degrees, more than 0 and less "
                         "than 180, got '%s'", v);
    o->fov = v;
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
void option_choices_text(const OptionChoice *c, int quoted, char *buf, size_t size)
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
    if (s->choices) option_choices_text(s->choices, 0, words, sizeof words);
    else snprintf(words, sizeof words, "%s", s->metavar ? s->metavar : "");
    if (s->kind != OPTION_SWITCH) snprintf(buf, size, " %s", words);
    else if (s->choices) snprintf(buf, size, "[=%s]", words);
    else if (size) buf[0] = '\0';
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
