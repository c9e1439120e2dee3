/* course_args.c — see course_args.h. */
#include "course_args.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "base/limit.h"
#include "types.h"

#define MIT_USAGE "usage: clpt -size W H -input FILE -output FILE [-normals FILE] " \
                  "[-depth NEAR FAR FILE] [-bounces N] [-shadows]"

/* Whether name ends in an image extension the course programs write. */
static int course_is_image_name(const char *name)
{
    const char *dot = strrchr(name, '.');
    return dot && (strcasecmp(dot, ".bmp") == 0 || strcasecmp(dot, ".png") == 0 || strcasecmp(dot, ".ppm") == 0);
}

CourseStyle course_args_style(int argc, char **argv)
{
    if (argc >= 2 && (strcmp(argv[1], "-size") == 0 || strcmp(argv[1], "-input") == 0)) return COURSE_MIT;
    if (argc < 3 || argv[1][0] == '-' || argv[2][0] == '-' || !course_is_image_name(argv[2])) return COURSE_NONE;
    return argc == 3 || strncmp(argv[3], "--", 2) == 0 ? COURSE_TSINGHUA : COURSE_NONE;
}

/* What every course program does: one ray through each pixel centre, the Whitted ray
 * caster, 8-bit values without the sRGB curve, no shadows and no secondary rays unless
 * asked for (MIT's -shadows and -bounces). */
static void course_defaults(Options *o)
{
    o->integrator = INTEGRATOR_WHITTED;
    o->spp = 1;
    o->gamma = 1;
    o->shadows = 0;
    o->max_depth = 0;
}

static Status course_long(const char *flag, const char *s, long lo, long hi, long *out, Error *err)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (!*s || *end || errno || v < lo || v > hi)
        return error_set(err, ST_USAGE, "%s expects an integer in %ld..%ld, got '%s' (" MIT_USAGE ")", flag, lo,
                         hi, s);
    *out = v;
    return ST_OK;
}

static Status course_distance(const char *what, const char *s, double *out, Error *err)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (!*s || *end || errno || !isfinite(v) || v < 0.0)
        return error_set(err, ST_USAGE, "-depth expects %s as a distance >= 0, got '%s' (" MIT_USAGE ")", what, s);
    *out = v;
    return ST_OK;
}

/* The n values of flag argv[i] must exist and not be flags (so that '-size 64 -input'
 * names what is missing); a negative number passes here and fails its range check. */
static Status course_values(int argc, char **argv, int i, int n, const char *what, Error *err)
{
    for (int k = 1; k <= n; k++)
        if (i + k >= argc || (argv[i + k][0] == '-' && argv[i + k][1] && !isdigit((unsigned char)argv[i + k][1]) &&
                              argv[i + k][1] != '.'))
            return error_set(err, ST_USAGE, "%s needs %s (" MIT_USAGE ")", argv[i], what);
    return ST_OK;
}

/* -depth NEAR FAR FILE: the course draws (t - near) / (far - near) from black to white
 * (NEAR > FAR turns it round, as in the course); clpt's --depth-range A,B draws white
 * at A and black at B, so this is --depth-range FAR,NEAR. */
static Status course_depth(char **v, Options *o, Error *err)
{
    double near, far;
    Status st = course_distance("NEAR", v[0], &near, err);
    if (!st) st = course_distance("FAR", v[1], &far, err);
    if (st) return st;
    if (far == near)
        return error_set(err, ST_USAGE, "-depth NEAR FAR FILE needs NEAR and FAR to differ, got %s and %s (" MIT_USAGE
                         ")", v[0], v[1]);
    o->depth_near = far;
    o->depth_far = near;
    o->aovs |= 1u << INTEGRATOR_AOV_DEPTH;
    o->aov_files[INTEGRATOR_AOV_DEPTH - INTEGRATOR_AOV_NORMAL] = v[2];
    return ST_OK;
}

/* One MIT flag at argv[*i] with its values (advancing *i past them). */
static Status course_mit_flag(int argc, char **argv, int *i, Options *o, Error *err)
{
    const char *a = argv[*i];
    Status st;
    long n;
    if (strcmp(a, "-shadows") == 0) {
        o->shadows = 1;
        return ST_OK;
    }
    enum { SIZE, INPUT, OUTPUT, NORMALS, DEPTH, BOUNCES, N_FLAGS };
    static const struct { const char *name; int n; const char *what; } flags[N_FLAGS] = {
        [SIZE] = { "-size", 2, "a width and a height" }, [INPUT] = { "-input", 1, "a scene file" },
        [OUTPUT] = { "-output", 1, "an image file" },   [NORMALS] = { "-normals", 1, "an image file" },
        [DEPTH] = { "-depth", 3, "NEAR FAR FILE" },     [BOUNCES] = { "-bounces", 1, "a number of bounces" },
    };
    int k = 0;
    while (k < N_FLAGS && strcmp(a, flags[k].name) != 0) k++;
    if (k == N_FLAGS && a[0] != '-')
        return error_set(err, ST_USAGE, "unexpected argument '%s' in the course command line (" MIT_USAGE ")", a);
    if (k == N_FLAGS)
        return error_set(err, ST_USAGE, "unknown option '%s' in the course command line (" MIT_USAGE ")", a);
    if ((st = course_values(argc, argv, *i, flags[k].n, flags[k].what, err))) return st;
    char **v = argv + *i + 1;
    *i += flags[k].n;
    if (k == SIZE) {
        if ((st = course_long("-size", v[0], 1, CLPT_MAX_IMAGE_SIDE, &o->width, err))) return st;
        return course_long("-size", v[1], 1, CLPT_MAX_IMAGE_SIDE, &o->height, err);
    }
    if (k == INPUT) o->scene_path = v[0];
    if (k == OUTPUT) o->output = v[0];
    if (k == NORMALS) {
        o->aovs |= 1u << INTEGRATOR_AOV_NORMAL;
        o->aov_files[INTEGRATOR_AOV_NORMAL - INTEGRATOR_AOV_NORMAL] = v[0];
    }
    if (k == DEPTH) return course_depth(v, o, err);
    if (k == BOUNCES) {
        if ((st = course_long("-bounces", v[0], 0, CLPT_MAX_DEPTH, &n, err))) return st;
        o->max_depth = n;
    }
    return ST_OK;
}

static Status course_parse_mit(int argc, char **argv, Options *o, int *next, Error *err)
{
    int i = 1;
    for (; i < argc && strncmp(argv[i], "--", 2) != 0; i++) {
        Status st = course_mit_flag(argc, argv, &i, o, err);
        if (st) return st;
    }
    *next = i;
    if (!o->scene_path) return error_set(err, ST_USAGE, "the course command line needs -input FILE (" MIT_USAGE ")");
    if (!o->output) return error_set(err, ST_USAGE, "the course command line needs -output FILE (" MIT_USAGE ")");
    return ST_OK;
}

Status course_args_parse(CourseStyle style, int argc, char **argv, Options *o, int *next, Error *err)
{
    course_defaults(o);
    if (style == COURSE_MIT) return course_parse_mit(argc, argv, o, next, err);
    o->scene_path = argv[1];
    o->output = argv[2];
    *next = 3;
    return ST_OK;
}
