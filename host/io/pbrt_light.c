/* pbrt_light.c — pbrt-v4 lights (pbrt_reader.h, docs/pbrt.md). */
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


/* ------------------------------------------------------------------ lights */

Status pbrt_area_light(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    (void)kw;
    Status st = ST_OK;
    if (!pbrt_tok_eq(type, "diffuse"))
        return lex_error_at(lx, type, p->err, "area light \"%.*s\" is not supported (diffuse is)",
                            (int)(type->len > 40 ? 40 : type->len), type->text);
    vec3 L = v3(1, 1, 1);
    double scale = 1;
    int two = 0;
    if ((st = pbrt_get_spectrum(p, lx, "L", &L, NULL, NULL)) || (st = pbrt_get_float(p, lx, "scale", &scale)) ||
        (st = pbrt_get_bool(p, lx, "twosided", &two)))
        return st;
    if (!(scale >= 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "scale"), ">= 0");
    p->g.area = 1;
    p->g.area_L = v3_scale(L, (float)scale);
    p->g.area_twosided = two;
    p->g.area_material = NO_INDEX;
    return pbrt_warn_unused(p, lx, "AreaLightSource");
}

vec3 pbrt_xf_dir(const Transform *t, vec3 d)
{
    vec3 o = transform_point(t, v3(0, 0, 0)), e = transform_point(t, d);
    return v3_sub(e, o);
}

static Status light_dir(Parser *p, const Lexer *lx, const Token *at, vec3 d, vec3 *out)
{
    double l = sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
    if (!(l > 0) || !isfinite(l)) return lex_error_at(lx, at, p->err, "the light's 'from' and 'to' are the same point");
    *out = v3((float)(d.x / l), (float)(d.y / l), (float)(d.z / l));
    return ST_OK;
}

/* pbrt-v4's ImageInfiniteLight: the square map at `f` (beside the main file), in the
 * light's frame (the CTM), scaled by `scale` (octa_env.h). */
static Status infinite_map(Parser *p, const Lexer *lx, const Token *f, double scale, double illuminance)
{
    char *path = pbrt_beside_main(p, f);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    float *rgb = NULL;
    int w = 0, h = 0;
    Status st = texture_read_rgb(path, 0, &rgb, &w, &h, p->err);
    free(path);
    if (st) {
        reader_annotate(lx, f, p->err);
        return st;
    }
    int finite = 1, invertible;
    size_t n = (size_t)w * (size_t)h * 3u;
    for (size_t i = 0; i < n && finite; i++) finite = isfinite(rgb[i]);
    Transform inv = transform_inverse(&p->g.ctm, &invertible);
    if (w != h) {
        st = lex_error_at(lx, f, p->err, "the infinite light's map is %dx%d; pbrt-v4's maps are square (equal-area "
                          "octahedral)", w, h);
    } else if (!finite) {
        st = lex_error_at(lx, f, p->err, "the infinite light's map has infinite or NaN pixels");
    } else if (!invertible) {
        st = lex_error_at(lx, f, p->err, "the infinite light's transform cannot be inverted");
    } else {
        if (illuminance > 0) {
            /* pbrt-v4's normalisation: the map's illuminance on an upward (+z) surface,
             * a sum over the upper hemisphere's texels of luminance x cos(theta) times
             * 2 pi / texels (its code's factor; each texel spans 4 pi / texels) */
            double k_e = 0;
            for (int y = 0; y < h; y++)
                for (int x = 0; x < w; x++) {
                    double d[3];
                    octa_square_to_sphere((x + 0.5) / w, (y + 0.5) / h, d);
                    if (d[2] <= 0) continue;
                    const float *t = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
                    k_e += (0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2]) * d[2];
                }
            k_e *= 2 * M_PI / ((double)w * h);
            if (k_e > 0) scale *= illuminance / k_e;
        }
        double m[9];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) m[3 * i + j] = inv.m[i][j];
        st = octa_env_set(p->s, rgb, (uint)w, m, (float)scale, p->err);
    }
    free(rgb);
    return st;
}

/* LightSource "infinite": a constant L, or an image (never both, as in pbrt); clpt has
 * one background, so a second light with a map is ignored with a warning, and a map
 * replaces the constants before it. */
static Status infinite_light(Parser *p, const Lexer *lx, const Token *type, double scale)
{
    vec3 c = v3(1, 1, 1);
    int has_L = 0;
    const Token *f = NULL;
    double illuminance = -1;
    Status st;
    if ((st = pbrt_get_spectrum(p, lx, "L", &c, NULL, &has_L)) || (st = pbrt_get_string(p, lx, "filename", &f)) ||
        (st = pbrt_get_float(p, lx, "illuminance", &illuminance)))
        return st;
    pbrt_param_find(p, "portal");   /* a sampling aid only */
    if (f && has_L)
        return lex_error_at(lx, type, p->err, "an infinite light takes \"L\" or \"filename\", not both");
    if (p->s->bg_type == BG_MAP)
        return warn_once(p, lx, type, "infinite-second", "clpt has one environment map: this infinite light is "
                         "ignored");
    if (f) {
        if (p->s->bg_type == BG_CONSTANT && !v3_is_zero(p->s->bg_color) &&
            (st = warn_once(p, lx, type, "infinite-replace", "clpt has one background: the infinite light's map "
                            "replaces the constant ones before it")))
            return st;
        return infinite_map(p, lx, f, scale, illuminance);
    }
    /* pbrt-v4: a uniform hemisphere of radiance L gives illuminance pi L */
    if (illuminance > 0) scale *= illuminance / M_PI;
    p->s->bg_type = BG_CONSTANT;
    p->s->bg_color = v3_add(p->s->bg_color, v3_scale(c, (float)scale));
    return ST_OK;
}

Status pbrt_light(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    (void)kw;
    Status st = ST_OK;
    /* pbrt-v4 too uses a moving light's start transform */
    if (pbrt_ctm_moves(p) && (st = pbrt_warn_still(p, lx, type, "a LightSource"))) return st;
    double scale = 1;
    if ((st = pbrt_get_float(p, lx, "scale", &scale))) return st;
    vec3 from = v3(0, 0, 0), to = v3(0, 0, 1), c = v3(1, 1, 1);
    if ((st = pbrt_get_point(p, lx, "from", &from)) || (st = pbrt_get_point(p, lx, "to", &to))) return st;
    if (pbrt_tok_eq(type, "point") || pbrt_tok_eq(type, "spot")) {
        int spot = pbrt_tok_eq(type, "spot");
        if ((st = pbrt_get_spectrum(p, lx, "I", &c, NULL, NULL))) return st;
        Light l = light_default(spot ? LIGHT_SPOT : LIGHT_POINT);
        l.intensity = v3_scale(c, (float)scale);
        l.position = transform_point(&p->g.ctm, from);
        if (spot) {
            double cone = 30, delta = 5;
            if ((st = pbrt_get_float(p, lx, "coneangle", &cone)) || (st = pbrt_get_float(p, lx, "conedelta", &delta))) return st;
            if (!(cone > 0 && cone < 180)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "coneangle"), "in (0, 180)");
            if (!(delta >= 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "conedelta"), ">= 0");
            if ((st = light_dir(p, lx, type, pbrt_xf_dir(&p->g.ctm, v3_sub(to, from)), &l.direction))) return st;
            l.cos_outer = (float)cos(cone * M_PI / 180);
            l.cos_inner = (float)cos(fmax(cone - delta, 0) * M_PI / 180);
        }
        if ((st = scene_add_light(p->s, l, p->err))) return st;
    } else if (pbrt_tok_eq(type, "distant")) {
        if ((st = pbrt_get_spectrum(p, lx, "L", &c, NULL, NULL))) return st;
        Light l = light_default(LIGHT_DIRECTIONAL);
        l.intensity = v3_scale(c, (float)scale);
        if ((st = light_dir(p, lx, type, pbrt_xf_dir(&p->g.ctm, v3_sub(to, from)), &l.direction))) return st;
        if ((st = scene_add_light(p->s, l, p->err))) return st;
    } else if (pbrt_tok_eq(type, "infinite")) {
        if ((st = infinite_light(p, lx, type, scale))) return st;
    } else {
        char key[96];
        snprintf(key, sizeof key, "LightSource %.*s", (int)(type->len > 40 ? 40 : type->len), type->text);
        for (size_t i = 0; i < p->pl.n; i++) p->pl.p[i].used = 1;
        return warn_once(p, lx, type, key, "LightSource \"%.*s\" is not supported; skipped",
                         (int)(type->len > 40 ? 40 : type->len), type->text);
    }
    return pbrt_warn_unused(p, lx, "LightSource");
}
