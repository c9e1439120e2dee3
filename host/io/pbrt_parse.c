/* pbrt_parse.c — the pbrt-v4 scene reader (pbrt_parse.h, docs/pbrt.md): the directive loop,
 * transforms and graphics state; the parts are in pbrt_reader.h. */
#include "io/pbrt_parse.h"
#include "io/pbrt_reader.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/limit.h"
#include "base/strmap.h"
#include "io/image_write.h"
#include "io/lexer.h"
#include "io/mesh_load.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "util/kmath.h"
#include "scene/mesh_sink.h"
#include "scene/octa_env.h"
#include "scene/subdiv.h"
#include "scene/transform.h"


/* ------------------------------------------------------------------ transforms */

/* The transform directives that take numbers: how many, what they are (for messages),
 * and the transform they make of them. Transform replaces the CTM; the others are
 * applied to it (CTM = CTM * t), as pbrt does. */
typedef Status (*XformBuild)(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t);

static Status build_translate(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    (void)p; (void)lx; (void)kw;
    *t = transform_translate(v[0], v[1], v[2]);
    return ST_OK;
}

static Status build_scale(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    (void)p; (void)lx; (void)kw;
    *t = transform_scale(v[0], v[1], v[2]);
    return ST_OK;
}

static Status build_rotate(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    if (v[1] == 0 && v[2] == 0 && v[3] == 0) return lex_error_at(lx, kw, p->err, "Rotate about a zero axis");
    *t = transform_rotate(v[1], v[2], v[3], v[0]);
    return ST_OK;
}

/* pbrt's 16 numbers are the matrix column by column; the last row must be 0 0 0 1 */
static Status build_matrix(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    if (v[3] != 0 || v[7] != 0 || v[11] != 0 || v[15] != 1)
        return lex_error_at(lx, kw, p->err, "a projective transform (its last row is not 0 0 0 1) is not supported");
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) t->m[r][c] = v[c * 4 + r];
    return ST_OK;
}

static Status build_lookat(Parser *p, const Lexer *lx, const Token *kw, const double *v, Transform *t)
{
    double dir[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]};
    double dl = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double ul = sqrt(v[6] * v[6] + v[7] * v[7] + v[8] * v[8]);
    if (!(dl > 0) || !(ul > 0)) return lex_error_at(lx, kw, p->err, "LookAt: the eye and the point looked at are the same, or up is zero");
    for (int i = 0; i < 3; i++) dir[i] /= dl;
    double up[3] = {v[6] / ul, v[7] / ul, v[8] / ul};
    /* right = up x dir, as pbrt: its camera space is left-handed */
    double r[3] = {up[1] * dir[2] - up[2] * dir[1], up[2] * dir[0] - up[0] * dir[2], up[0] * dir[1] - up[1] * dir[0]};
    double rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(rl > 1e-9)) return lex_error_at(lx, kw, p->err, "LookAt: up is parallel to the view direction");
    for (int i = 0; i < 3; i++) r[i] /= rl;
    double nu[3] = {dir[1] * r[2] - dir[2] * r[1], dir[2] * r[0] - dir[0] * r[2], dir[0] * r[1] - dir[1] * r[0]};
    Transform w;
    for (int i = 0; i < 3; i++) {
        w.m[i][0] = r[i];
        w.m[i][1] = nu[i];
        w.m[i][2] = dir[i];
        w.m[i][3] = v[i];
    }
    int ok;
    *t = transform_inverse(&w, &ok);
    return ST_OK;
}

static const struct {
    const char *name;
    int numbers;
    const char *what;         /* for "expected <what>" */
    XformBuild build;
    int replace;              /* the CTM becomes the transform */
} xform_directives[] = {
    {"Translate", 3, "a number (Translate x y z)", build_translate, 0},
    {"Scale", 3, "a number (Scale x y z)", build_scale, 0},
    {"Rotate", 4, "a number (Rotate degrees x y z)", build_rotate, 0},
    {"LookAt", 9, "a number (LookAt eye, look, up)", build_lookat, 0},
    {"Transform", 16, "a number (16 matrix entries)", build_matrix, 1},
    {"ConcatTransform", 16, "a number (16 matrix entries)", build_matrix, 0},
};

/* Translate, Scale, Rotate, LookAt, Transform, ConcatTransform: by the table above. */
static Status d_xform(Parser *p, Lexer *lx, const Token *kw)
{
    size_t i = 0, n = sizeof xform_directives / sizeof xform_directives[0];
    while (i < n && !pbrt_tok_eq(kw, xform_directives[i].name)) i++;
    if (i == n) return error_set(p->err, ST_INTERNAL, "no transform directive '%.*s'", (int)kw->len, kw->text);
    double v[16];
    Transform t;
    Status st = pbrt_expect_numbers(p, lx, v, xform_directives[i].numbers, xform_directives[i].what);
    if (!st) st = xform_directives[i].build(p, lx, kw, v, &t);
    if (st) return st;
    /* each active transform of the two (ActiveTransform) takes it */
    if (p->g.active & PBRT_ACTIVE_START) p->g.ctm = xform_directives[i].replace ? t : transform_compose(&p->g.ctm, &t);
    if (p->g.active & PBRT_ACTIVE_END)
        p->g.ctm_end = xform_directives[i].replace ? t : transform_compose(&p->g.ctm_end, &t);
    return ST_OK;
}

int pbrt_ctm_moves(const Parser *p)
{
    return memcmp(&p->g.ctm, &p->g.ctm_end, sizeof p->g.ctm) != 0;
}

Status pbrt_warn_still(Parser *p, const Lexer *lx, const Token *at, const char *what)
{
    char key[96];
    snprintf(key, sizeof key, "still %s", what);
    return warn_once(p, lx, at, key, "%s under a moving transform (ActiveTransform) stands still at its start-time "
                     "pose: only ObjectInstances and the camera move (docs/pbrt.md#motion)", what);
}

/* A coordinate system's pair of transforms, new or replaced, as name t. */
static Status coordsys_set(Parser *p, const Token *t, const Transform *start, const Transform *end)
{
    uint32_t i;
    if (!strmap_find(&p->coordsys, t->text, t->len, &i)) {
        if (pbrt_grow((void **)&p->coordsys_xf, &p->cap_coordsys, p->n_coordsys + 1, sizeof(PTransformPair)) ||
            strmap_add(&p->coordsys, t->text, t->len, (uint32_t)p->n_coordsys))
            return error_set(p->err, ST_INTERNAL, "out of memory");
        i = (uint32_t)p->n_coordsys++;
    }
    p->coordsys_xf[i] = (PTransformPair){*start, *end};
    return ST_OK;
}

static Status d_coordsys(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token t;
    Status st = pbrt_expect_string(p, lx, "a quoted coordinate system name", &t);
    if (st) return st;
    return coordsys_set(p, &t, &p->g.ctm, &p->g.ctm_end);
}

static Status d_coordsys_transform(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token t;
    uint32_t i;
    Status st = pbrt_expect_defined(p, lx, &p->coordsys, "coordinate system", "CoordinateSystem", &t, &i);
    if (st) return st;
    if (p->g.active & PBRT_ACTIVE_START) p->g.ctm = p->coordsys_xf[i].start;
    if (p->g.active & PBRT_ACTIVE_END) p->g.ctm_end = p->coordsys_xf[i].end;
    return ST_OK;
}

static Status d_identity(Parser *p, Lexer *lx, const Token *kw)
{
    (void)lx; (void)kw;
    if (p->g.active & PBRT_ACTIVE_START) p->g.ctm = transform_identity();
    if (p->g.active & PBRT_ACTIVE_END) p->g.ctm_end = transform_identity();
    return ST_OK;
}

static Status d_reverse(Parser *p, Lexer *lx, const Token *kw)
{
    (void)lx; (void)kw;
    p->g.reverse = !p->g.reverse;
    return ST_OK;
}

/* ------------------------------------------------------------------ attributes */

Status pbrt_push_state(Parser *p)
{
    if (pbrt_grow((void **)&p->stack, &p->cap_stack, p->n_stack + 1, sizeof(GState)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    p->stack[p->n_stack++] = p->g;
    return ST_OK;
}

static Status d_attr_begin(Parser *p, Lexer *lx, const Token *kw)
{
    (void)lx; (void)kw;
    return pbrt_push_state(p);
}

static Status d_attr_end(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->n_stack == 0) return lex_error_at(lx, kw, p->err, "%.*s without a matching begin", (int)kw->len, kw->text);
    p->g = p->stack[--p->n_stack];
    return ST_OK;
}

/* TransformBegin/End (pbrt-v3, deprecated in v4) keep only the transform */
static Status d_transform_end(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->n_stack == 0) return lex_error_at(lx, kw, p->err, "TransformEnd without a matching TransformBegin");
    --p->n_stack;
    p->g.ctm = p->stack[p->n_stack].ctm;
    p->g.ctm_end = p->stack[p->n_stack].ctm_end;
    return ST_OK;
}

static Status d_world_begin(Parser *p, Lexer *lx, const Token *kw)
{
    if (p->world) return lex_error_at(lx, kw, p->err, "WorldBegin given twice");
    p->world = 1;
    p->g.ctm = p->g.ctm_end = transform_identity();
    p->g.active = PBRT_ACTIVE_ALL; /* pbrt-v4's WorldBegin makes both transforms active again */
    Token t = {TOK_STRING, "world", 5, kw->line, kw->col};
    uint32_t i;
    if (!strmap_find(&p->coordsys, t.text, t.len, &i)) return coordsys_set(p, &t, &p->g.ctm, &p->g.ctm_end);
    return ST_OK;
}

/* ------------------------------------------------------------------ options */

static Status d_camera(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    Status st = ST_OK;
    if (!pbrt_tok_eq(type, "perspective") && !pbrt_tok_eq(type, "orthographic")) {
        st = warn_once(p, lx, type, "Camera", "Camera \"%.*s\" is not supported; a perspective camera is used",
                       (int)(type->len > 40 ? 40 : type->len), type->text);
        if (st) return st;
    }
    p->have_camera = 1;
    p->s->camera_medium = p->g.medium_out;   /* pbrt-v4's CameraMedium: the outside one now */
    p->cam_ortho = pbrt_tok_eq(type, "orthographic");
    p->cam_from_world = p->g.ctm;
    p->cam_from_world_end = p->g.ctm_end;
    p->cam_time_start = p->time_start;
    p->cam_time_end = p->time_end;
    p->fov = 90;
    p->lens_radius = 0;
    p->focal_distance = 1e6;
    if ((st = pbrt_get_float(p, lx, "fov", &p->fov)) || (st = pbrt_get_float(p, lx, "lensradius", &p->lens_radius)) ||
        (st = pbrt_get_float(p, lx, "focaldistance", &p->focal_distance)))
        return st;
    if (!(p->fov > 0 && p->fov < 180)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "fov"), "in (0, 180) degrees");
    if (!(p->lens_radius >= 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "lensradius"), ">= 0");
    if (!(p->focal_distance > 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "focaldistance"), "> 0");
    /* pbrt-v4's CameraBase: the shutter is open from 0 to 1 unless given; one that
     * closes before it opens is swapped, with a warning, as pbrt does */
    double open = 0, close = 1;
    if ((st = pbrt_get_float(p, lx, "shutteropen", &open)) || (st = pbrt_get_float(p, lx, "shutterclose", &close)))
        return st;
    if (!isfinite(open) || !isfinite(close) || fabs(open) > 1e30 || fabs(close) > 1e30)
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, isfinite(open) && fabs(open) <= 1e30 ? "shutterclose"
                                                                                                    : "shutteropen"),
                                     "a finite time");
    if (close < open) {
        st = warn_once(p, lx, kw, "shutter swap", "Camera \"shutterclose\" %g is before \"shutteropen\" %g: they are "
                       "swapped, as pbrt-v4 does", close, open);
        if (st) return st;
        double t = open;
        open = close;
        close = t;
    }
    p->s->camera.shutter_open = (float)open;
    p->s->camera.shutter_close = (float)close;
    /* the camera's coordinate system, as pbrt names it */
    Token cn = {TOK_STRING, "camera", 6, kw->line, kw->col};
    int ok, ok_end;
    Transform wfc = transform_inverse(&p->g.ctm, &ok), wfc_end = transform_inverse(&p->g.ctm_end, &ok_end);
    if (!ok) return lex_error_at(lx, kw, p->err, "the camera transform is singular");
    if (!ok_end) return lex_error_at(lx, kw, p->err, "the camera's end-time transform (ActiveTransform EndTime) is singular");
    if ((st = coordsys_set(p, &cn, &wfc, &wfc_end))) return st;
    return pbrt_warn_unused(p, lx, "Camera");
}

/* Film "pixelbounds" [x0 x1 y0 y1] (integers) or "cropwindow" (floats): the window
 * clpt renders, as --pixel-bounds and --crop (scene/crop.h). As pbrt-v4: pixelbounds
 * wins when both are given (with a warning), and a crop window's bounds are put in
 * order and clamped to [0, 1]. A window that selects no pixel, or pixel bounds past the
 * image, is refused once the image's size is final (--width may change it). */
static Status film_crop(Parser *p, Lexer *lx, const Token *kw)
{
    Param *pb = pbrt_param_find(p, "pixelbounds"), *cw = pbrt_param_find(p, "cropwindow");
    if (pb && (pb->type != PT_INTEGER || pb->n != 4)) return pbrt_param_type_error(p, lx, pb, "four integers");
    if (cw && ((cw->type != PT_FLOAT && cw->type != PT_INTEGER) || cw->n != 4))
        return pbrt_param_type_error(p, lx, cw, "four floats");
    Status st;
    if (pb && cw && (st = warn_once(p, lx, kw, "Film crop", "Film has both \"pixelbounds\" and \"cropwindow\"; "
                                    "pixelbounds is used, as pbrt does")))
        return st;
    SceneCrop *c = &p->s->crop;
    if (pb) {
        const double *v = p->pl.nums + pb->first;
        for (int i = 0; i < 4; i++)
            if (v[i] < 0) return pbrt_param_type_error(p, lx, pb, "four integers >= 0");
        *c = (SceneCrop){ CROP_PIXELS, v[0], v[1], v[2], v[3] };
    } else if (cw) {
        const double *v = p->pl.nums + cw->first;
        *c = (SceneCrop){ CROP_FRACTIONS, fmin(fmax(fmin(v[0], v[1]), 0.0), 1.0), fmin(fmax(fmax(v[0], v[1]), 0.0), 1.0),
                          fmin(fmax(fmin(v[2], v[3]), 0.0), 1.0), fmin(fmax(fmax(v[2], v[3]), 0.0), 1.0) };
    }
    return ST_OK;
}

static Status d_film(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    (void)type;
    Status st;
    long w = 1280, h = 720;   /* pbrt-v4's defaults */
    if ((st = pbrt_get_int_in(p, lx, "xresolution", 1, CLPT_MAX_IMAGE_SIDE, &w)) ||
        (st = pbrt_get_int_in(p, lx, "yresolution", 1, CLPT_MAX_IMAGE_SIDE, &h)))
        return st;
    p->s->image.width = (uint)w;
    p->s->image.height = (uint)h;
    /* the image pbrt would write: clpt's output when -o does not name one (main.c) */
    const Token *f = NULL;
    if ((st = pbrt_get_string(p, lx, "filename", &f))) return st;
    if (f) {
        char *name = tok_copy(f);
        if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
        ImageFormat format;
        if (!name[0] || image_format_from_path(name, &format, p->err)) {
            free(name);
            return lex_error_at(lx, f, p->err, "Film \"filename\" '%.*s' is not an image clpt writes (.png, .ppm, "
                                ".bmp, .pfm, .exr, .hdr)", (int)(f->len > 60 ? 60 : f->len), f->text);
        }
        free(p->s->output_hint);
        p->s->output_hint = name;
    }
    if ((st = film_crop(p, lx, kw))) return st;
    return pbrt_warn_unused(p, lx, "Film");
}

static Status d_sampler(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    (void)kw;
    (void)type;
    Status st;
    long n = 16;
    if ((st = pbrt_get_int_in(p, lx, "pixelsamples", 1, CLPT_MAX_SPP, &n))) return st;
    p->s->image.spp = (uint)n;
    pbrt_param_find(p, "seed");   /* clpt's seed is its own; pbrt's only picks other noise */
    return pbrt_warn_unused(p, lx, "Sampler");
}

static Status d_integrator(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    (void)kw;
    Status st = ST_OK;
    if (!pbrt_tok_eq(type, "path") && !pbrt_tok_eq(type, "volpath")) {
        st = warn_once(p, lx, type, "Integrator", "Integrator \"%.*s\" is not supported; clpt's path tracer is used",
                       (int)(type->len > 40 ? 40 : type->len), type->text);
        if (st) return st;
    }
    long d = 5;
    if ((st = pbrt_get_int_in(p, lx, "maxdepth", 0, CLPT_MAX_DEPTH, &d))) return st;
    p->s->image.max_depth = (uint)d;
    pbrt_param_find(p, "regularize");
    return pbrt_warn_unused(p, lx, "Integrator");
}


/* ------------------------------------------------------------------ files */

static Status parse_file(Parser *p, const char *path, const char *text, size_t len);

static Status d_include(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = pbrt_expect_string(p, lx, "a quoted file name", &t);
    if (st) return st;
    if (p->depth + 1 >= CLPT_MAX_INCLUDE_DEPTH) {
        p->depth_exceeded = 1;
        return lex_error_at(lx, kw, p->err, "includes nested more than %d deep (does a file include itself?)",
                            CLPT_MAX_INCLUDE_DEPTH);
    }
    char *path = pbrt_beside_main(p, &t);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    /* the included file has a lexer of its own: nothing is pushed back across files */
    p->depth++;
    st = parse_file(p, path, NULL, 0);
    p->depth--;
    free(path);
    if (st != ST_IO && p->depth_exceeded) return st;
    return reader_note_nested(lx, &t, kw, "included from", st, p->err);
}

/* A directive clpt does not support: its arguments and parameters are skipped. */
static Status d_unsupported(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st;
    for (;;) {
        if ((st = lex_next(lx, &t, p->err))) return st;
        double d;
        int arg = t.kind == TOK_STRING || t.kind == TOK_LBRACKET || t.kind == TOK_RBRACKET ||
                  (t.kind == TOK_WORD && (pbrt_tok_double(&t, &d) == 0 || pbrt_tok_is_bool(&t)));
        if (!arg) break;
    }
    lex_unread(lx, &t);
    char key[64];
    snprintf(key, sizeof key, "%.*s", (int)(kw->len > 40 ? 40 : kw->len), kw->text);
    return warn_once(p, lx, kw, key, "%s is not supported; ignored", key);
}

/* ActiveTransform StartTime | EndTime | All (a bare word, not a string): the transforms
 * the transform directives change from now on (docs/pbrt.md#motion). AttributeBegin/End
 * keep the setting with the rest of the graphics state, as pbrt-v4's does. */
static Status d_active_transform(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if (t.kind == TOK_WORD && pbrt_tok_eq(&t, "StartTime"))
        p->g.active = PBRT_ACTIVE_START;
    else if (t.kind == TOK_WORD && pbrt_tok_eq(&t, "All"))
        p->g.active = PBRT_ACTIVE_ALL;
    else if (t.kind == TOK_WORD && pbrt_tok_eq(&t, "EndTime"))
        p->g.active = PBRT_ACTIVE_END;
    else
        return lex_expected(lx, &t, "StartTime, EndTime or All (ActiveTransform)", p->err);
    return ST_OK;
}

/* TransformTimes start end: the times of the two transforms (0 and 1 unless given),
 * an option before WorldBegin as in pbrt-v4. An end before the start is refused. */
static Status d_transform_times(Parser *p, Lexer *lx, const Token *kw)
{
    double v[2];
    Status st = pbrt_expect_numbers(p, lx, v, 2, "a number (TransformTimes start end)");
    if (st) return st;
    if (!isfinite(v[0]) || !isfinite(v[1]) || fabs(v[0]) > 1e30 || fabs(v[1]) > 1e30)
        return lex_error_at(lx, kw, p->err, "TransformTimes: the times must be finite numbers");
    if (v[1] < v[0])
        return lex_error_at(lx, kw, p->err, "TransformTimes: the end time %g is before the start time %g", v[1], v[0]);
    p->time_start = v[0];
    p->time_end = v[1];
    return ST_OK;
}

static Status d_ignored(Parser *p, Lexer *lx, const Token *kw)
{
    (void)p; (void)lx; (void)kw;
    return ST_OK;
}

/* The directives: `fn` reads all that follows its keyword; `headed`, the directives
 * whose head is one quoted string (a type or a name, `head` says which) and a parameter
 * list, gets the head read and the parameters in p->pl (pbrt_expect_head); the options
 * that must come before WorldBegin say so. */
static const struct {
    const char *name;
    Status (*fn)(Parser *p, Lexer *lx, const Token *kw);
    Status (*headed)(Parser *p, Lexer *lx, const Token *kw, const Token *head);
    const char *head;
    int before_world;
} directives[] = {
    {"Translate", .fn = d_xform},
    {"Scale", .fn = d_xform},
    {"Rotate", .fn = d_xform},
    {"LookAt", .fn = d_xform},
    {"Transform", .fn = d_xform},
    {"ConcatTransform", .fn = d_xform},
    {"CoordinateSystem", .fn = d_coordsys},
    {"CoordSysTransform", .fn = d_coordsys_transform},
    {"Identity", .fn = d_identity},
    {"ReverseOrientation", .fn = d_reverse},
    {"AttributeBegin", .fn = d_attr_begin},
    {"AttributeEnd", .fn = d_attr_end},
    {"TransformBegin", .fn = d_attr_begin},
    {"TransformEnd", .fn = d_transform_end},
    {"WorldBegin", .fn = d_world_begin},
    {"WorldEnd", .fn = d_ignored},        /* pbrt-v3's end of file */
    {"Camera", .headed = d_camera, .head = "a quoted camera type", .before_world = 1},
    {"Film", .headed = d_film, .head = "a quoted film type", .before_world = 1},
    {"Sampler", .headed = d_sampler, .head = "a quoted sampler type", .before_world = 1},
    {"Integrator", .headed = d_integrator, .head = "a quoted integrator type", .before_world = 1},
    {"Material", .headed = pbrt_material, .head = "a quoted material type"},
    {"MakeNamedMaterial", .headed = pbrt_make_named_material, .head = "a quoted material name"},
    {"NamedMaterial", .fn = pbrt_named_material},
    {"Texture", .fn = pbrt_texture},
    {"AreaLightSource", .headed = pbrt_area_light, .head = "a quoted area light type"},
    {"LightSource", .headed = pbrt_light, .head = "a quoted light type"},
    {"Shape", .headed = pbrt_shape, .head = "a quoted shape type"},
    {"Include", .fn = d_include},
    {"Import", .fn = d_include},
    {"PixelFilter", .fn = d_unsupported},
    {"ColorSpace", .fn = d_unsupported},
    {"Option", .fn = d_unsupported},
    {"Accelerator", .fn = d_unsupported},
    {"TransformTimes", .fn = d_transform_times, .before_world = 1},
    {"ActiveTransform", .fn = d_active_transform},
    {"MakeNamedMedium", .fn = pbrt_make_named_medium},
    {"MediumInterface", .fn = pbrt_medium_interface},
    {"Attribute", .fn = d_unsupported},
    {"ObjectBegin", .fn = pbrt_object_begin},
    {"ObjectEnd", .fn = pbrt_object_end},
    {"ObjectInstance", .fn = pbrt_object_instance},
};
#define N_DIRECTIVES (sizeof directives / sizeof directives[0])

static size_t directive_index(const Token *t)
{
    if (t->kind != TOK_WORD) return N_DIRECTIVES;
    for (size_t i = 0; i < N_DIRECTIVES; i++)
        if (pbrt_tok_eq(t, directives[i].name)) return i;
    return N_DIRECTIVES;
}

static Status parse_statements(Parser *p, Lexer *lx)
{
    Status st;
    for (;;) {
        Token t;
        if ((st = lex_next(lx, &t, p->err)) || t.kind == TOK_EOF) break;
        size_t i = directive_index(&t);
        if (i == N_DIRECTIVES) {
            st = lex_expected(lx, &t, "a pbrt directive (Shape, Material, LightSource, AttributeBegin, ...)", p->err);
            break;
        }
        if (p->world && directives[i].before_world) {
            st = lex_error_at(lx, &t, p->err, "%s must come before WorldBegin", directives[i].name);
            break;
        }
        if (directives[i].headed) {
            Token head;
            if ((st = pbrt_expect_head(p, lx, directives[i].head, &head)) ||
                (st = directives[i].headed(p, lx, &t, &head)))
                break;
        } else if ((st = directives[i].fn(p, lx, &t))) {
            break;
        }
    }
    return st;
}

static Status parse_file(Parser *p, const char *path, const char *text, size_t len)
{
    Lexer lx;
    Status st = text ? lex_open_text(&lx, path, text, len, p->err) : lex_open_file(&lx, path, p->err);
    if (st) return st;
    st = parse_statements(p, &lx);
    lex_close(&lx);
    return st;
}

/* ------------------------------------------------------------------ the camera */

/* The pose of pbrt's camera at cam_from_world (invertible: d_camera checks): from, at
 * one unit ahead, up, and whether pbrt's image right (the camera's +x) is the mirror of
 * clpt's (forward x up). */
static void camera_pose(const Transform *cam_from_world, vec3 *from, vec3 *at, vec3 *up, int *mirror_x)
{
    int ok;
    Transform w = transform_inverse(cam_from_world, &ok);
    vec3 o = transform_point(&w, v3(0, 0, 0));
    vec3 f = pbrt_xf_dir(&w, v3(0, 0, 1)), u = pbrt_xf_dir(&w, v3(0, 1, 0)), r = pbrt_xf_dir(&w, v3(1, 0, 0));
    float fl = sqrtf(v3_dot(f, f));
    *from = o;
    *at = v3_add(o, v3_scale(f, 1.0f / fl));
    *up = u;
    vec3 fu = v3(f.y * u.z - f.z * u.y, f.z * u.x - f.x * u.z, f.x * u.y - f.y * u.x);
    *mirror_x = v3_dot(fu, r) < 0;
}

/* A camera whose two transforms differ moves (docs/motion.md): its own pose at the
 * start time, a camera key at the end time. pbrt-v4 interpolates the camera's
 * world-from-camera transforms (translation linearly, rotation by slerp); clpt's camera
 * keys are the look-at frames of the poses, interpolated the same way, so a rigid
 * camera moves as in pbrt (a scale in the camera transform is dropped, as for a still
 * camera). */
static Status camera_motion(Parser *p)
{
    SceneCamera *c = &p->s->camera;
    c->time = (float)p->cam_time_start;
    if (memcmp(&p->cam_from_world, &p->cam_from_world_end, sizeof p->cam_from_world) == 0) return ST_OK;
    if (!(p->cam_time_end > p->cam_time_start))
        return error_set(p->err, ST_INPUT, "%s: the camera moves (ActiveTransform) but TransformTimes gives its start "
                         "and end the same time %g", p->top_path, p->cam_time_start);
    SceneCameraKey k = {.time = (float)p->cam_time_end};
    int mirror;
    camera_pose(&p->cam_from_world_end, &k.from, &k.at, &k.up, &mirror);
    if (mirror != c->mirror_x)
        return error_set(p->err, ST_INPUT, "%s: the camera's end-time transform mirrors the image and its start-time "
                         "one does not, or the other way round", p->top_path);
    SceneCameraKey *grown = realloc(p->s->camera_keys, (p->s->n_camera_keys + 1) * sizeof *grown);
    if (!grown) return error_set(p->err, ST_INTERNAL, "out of memory");
    p->s->camera_keys = grown;
    p->s->cap_camera_keys = p->s->n_camera_keys + 1;
    p->s->camera_keys[p->s->n_camera_keys++] = k;
    return ST_OK;
}

/* pbrt's camera at cam_from_world looks down its +z with +y up and +x to the image's
 * right; its field of view spans the shorter image side. */
static Status finish_camera(Parser *p)
{
    SceneCamera *c = &p->s->camera;
    if (!p->have_camera) {
        /* pbrt's default: at the origin looking down +z, fov 90 */
        p->cam_from_world = p->cam_from_world_end = transform_identity();
        p->fov = 90;
        p->lens_radius = 0;
        p->focal_distance = 1e6;
    }
    int ok;
    transform_inverse(&p->cam_from_world, &ok);
    if (!ok) return error_set(p->err, ST_INPUT, "%s: the camera transform is singular", p->top_path);
    camera_pose(&p->cam_from_world, &c->from, &c->at, &c->up, &c->mirror_x);
    Status st = camera_motion(p);
    if (st) return st;
    double w_px = p->s->image.width, h_px = p->s->image.height;
    double aspect = w_px / h_px;
    if (p->cam_ortho) {
        c->type = CAMERA_ORTHOGRAPHIC;
        /* the screen window is [-1, 1] on the shorter side */
        c->ortho_height = (float)(aspect >= 1 ? 2.0 : 2.0 / aspect);
        return ST_OK;
    }
    c->type = CAMERA_PERSPECTIVE;
    double half = tan(p->fov * M_PI / 360.0);
    c->vfov = (float)(aspect >= 1 ? p->fov : 360.0 / M_PI * atan(half / aspect));
    c->aperture = (float)(2 * p->lens_radius);
    c->focus_dist = p->lens_radius > 0 ? (float)p->focal_distance : 0.0f;
    return ST_OK;
}

/* ------------------------------------------------------------------ entry points */

int pbrt_detect(const char *text, size_t len)
{
    size_t i = 0;
    for (;;) {
        while (i < len && (text[i] == ' ' || text[i] == '\t' || text[i] == '\r' || text[i] == '\n')) i++;
        if (i < len && text[i] == '#') {
            while (i < len && text[i] != '\n') i++;
            continue;
        }
        break;
    }
    size_t s = i;
    while (i < len && ((text[i] >= 'A' && text[i] <= 'Z') || (text[i] >= 'a' && text[i] <= 'z'))) i++;
    Token t = {TOK_WORD, text + s, i - s, 1, 1};
    return i > s && directive_index(&t) < N_DIRECTIVES;
}

Status pbrt_load_text(const char *path, const char *text, size_t len, Scene *s, Error *err)
{
    Status path_st = scene_set_path(s, path, err);
    if (path_st) return path_st;
    Parser p = { .s = s, .err = err, .top_path = path,
                 .time_start = 0, .time_end = 1,   /* pbrt-v4's TransformTimes 0 1 */
                 .g = { .ctm = transform_identity(), .ctm_end = transform_identity(), .active = PBRT_ACTIVE_ALL,
                        .material = NO_INDEX, .area_material = NO_INDEX } };
    /* pbrt-v4's defaults where clpt's differ */
    s->image.width = 1280;
    s->image.height = 720;
    s->image.spp = 16;
    s->image.max_depth = 5;
    Status st = parse_file(&p, path, text, len);
    if (!st && p.in_object)
        st = error_set(err, ST_INPUT, "%s: ObjectBegin \"%s\" has no ObjectEnd before the end of the file", p.obj_where,
                       p.obj_name_buf);
    for (size_t i = 0; !st && i < p.n_pending; i++)
        if (!p.pending[i].defined)
            st = error_set(err, ST_INPUT, "%s is used by NamedMaterial and never defined (MakeNamedMaterial defines it)",
                           p.pending[i].where);
    if (!st) st = finish_camera(&p);
    if (!st) st = scene_check_precision(s, err);
    free(p.stack);
    free(p.pending);
    free(p.area_of_pending);
    free(p.coordsys_xf);
    free(p.tex);
    free(p.pl.p);
    free(p.pl.nums);
    free(p.pl.strs);
    strmap_free(&p.named_material);
    strmap_free(&p.named_medium);
    strmap_free(&p.coordsys);
    strmap_free(&p.tex_by_name);
    strmap_free(&p.warned);
    strmap_free(&p.object_by_name);
    pbrt_objects_free(&p);
    free(p.obj_name_buf);
    return st;
}
