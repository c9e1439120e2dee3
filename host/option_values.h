/* option_values.h — Options, what the command line asks for. Its own header so that
 * course_args.c, which fills it from the courses' command lines, needs nothing of
 * options.c, which calls it (no circle between the two). */
#ifndef CLPT_OPTION_VALUES_H
#define CLPT_OPTION_VALUES_H

/* --stats: none, the text tables (--stats), or one JSON object (--stats=json) */
enum { STATS_NONE, STATS_TEXT, STATS_JSON };
#define OPTIONS_MAX_SETS 64

typedef struct {
    const char *scene_path;
    const char *output;           /* NULL: <scene name>.png in the current folder */
    /* overrides of the scene file; -1 = keep the scene's value */
    long spp, width, height, seed, max_depth, split;
    const char *device_spec;      /* NULL: default selection */
    const char *camera;           /* --camera: the glTF camera, by index or name; NULL: first */
    int threads;                  /* scalar device workers, 0 = every core */
    double time_limit;            /* seconds, 0 = none */
    double progressive_seconds;   /* 0 = no progressive output */
    const char *checkpoint_path;  /* NULL: no checkpoints (but see resume_path) */
    double checkpoint_seconds;    /* between checkpoints; 60 unless given */
    const char *resume_path;      /* NULL: a fresh render */
    /* --sample-range A:B: render only sample indices [A, B) of every pixel (an
     * independent part for `clpt merge`); -1/-1 = all of [0, spp) */
    long range_first, range_end;
    /* --frames A:B: render frames A..B of the scene's animation (docs/animation.md) to
     * numbered outputs; -1/-1 = one image, no animation */
    long frames_first, frames_last;
    double fps;                   /* --fps: frames per second of animation time; 0 = 24 */
    double anim_time;             /* --time T: one image of the animation's pose at T
                                   * seconds; < 0: none (the file's own pose) */
    /* --shutter A:B: a glTF animation blurred over [A, B] seconds; 0 and 0: none */
    double shutter_open, shutter_close;
    double shutter_fraction;      /* --shutter F with --frames: open F of each frame's
                                   * time, from the frame's time; 0: none */
    /* under mpirun (docs/distributed.md) */
    int mpi_broadcast;            /* the scene is read by rank 0 only and sent to the others */
    double mpi_timeout;           /* seconds of silence before a rank is given up; 0 = 30 */
    int list_devices, profile, quiet, help, version;
    int stats;                    /* STATS_NONE, _TEXT or _JSON */
    int interactive;              /* --interactive: the viewer (docs/viewer.md) */
    int exr_float;                /* EXR channels as 32-bit floats, not halves */
    int denoise;                  /* --denoise: Open Image Denoise on the finished image */
    const char *display_server;   /* --display-server HOST:PORT (tev); NULL: none */
    unsigned jpeg_quality;        /* 1..100; 0: not given (IMAGE_JPEG_QUALITY) */
    int png_depth;                /* 8 or 16; 0: not given (8) */
    /* developer flags */
    const char *kernel_dir;
    unsigned batch;               /* fixed batch size, 0 = adaptive */
    unsigned wave_paths;          /* OpenCL wave size, 0 = automatic */
    int wave_launch;              /* enum WaveLaunch (device.h), 0 = by device type */
    /* the classic ray tracer (docs/classic-format.md) */
    int integrator;               /* enum Integrator (path or whitted), -1 = the scene's */
    int format;                   /* enum SceneFormat (io/scene_load.h) */
    unsigned aovs;                /* bit (INTEGRATOR_AOV_x): auxiliary images to write */
    const char *aov_files[3];     /* normal, depth, albedo image names (the course command
                                   * line); NULL: OUTPUT-normal.png etc. */
    double adaptive;              /* whitted: neighbour difference threshold, 0 = off */
    unsigned adaptive_spp;        /* extra samples per flagged pixel */
    double noise_threshold;       /* path: adaptive sampling's threshold, 0 = off */
    double clamp;                 /* path: --clamp's limit on indirect light, 0 = off */
    unsigned min_spp;             /* samples before it stops a pixel */
    int gamma;                    /* -1 the scene's, 0 sRGB, 1 none (linear 8-bit) */
    int shadows;                  /* -1 the scene's, 0 off, 1 on */
    int sampler;                  /* -1 the scene's, else enum Sampler */
    int accel;                    /* -1 the default, else enum SceneAccel */
    double depth_near, depth_far; /* --depth-range; near == far (0) = automatic */
    int view;                     /* --view: enum ViewTransform (io/view_transform.h) */
    double exposure;              /* --exposure: stops, before the view */
    /* --lookat and --fov, checked and kept as typed; applied as --set camera.from, .at,
     * .up and .fov are (scene_options.c). NULL: the scene's */
    const char *lookat;           /* "EX,EY,EZ,AX,AY,AZ,UX,UY,UZ" */
    const char *fov;              /* degrees, vertical */
    /* --crop or --pixel-bounds: the window of the image rendered (scene/crop.h) */
    unsigned crop_kind;           /* enum CropKind: 0 the scene's, else fractions or pixels */
    double crop[4];               /* x0, x1, y0, y1 as given */
    const char *crop_text;        /* the value as typed, for messages */
    /* --set KEY=VALUE, in the order given: scene parameters by path (scene/scene_param.h) */
    const char *sets[OPTIONS_MAX_SETS];
    unsigned n_sets;
} Options;

#endif /* CLPT_OPTION_VALUES_H */
