/*
 * pbrt_medium.c — the pbrt-v4 reader's participating media (docs/media.md,
 * docs/pbrt.md): MakeNamedMedium, MediumInterface, and the media a shape bounds and the
 * camera is in; part of the reader of pbrt_parse.c (pbrt_reader.h).
 *
 * pbrt-v4 keeps an inside and an outside medium in the graphics state (MediumInterface
 * sets them, AttributeBegin/End saves and restores them); every shape made afterwards
 * bounds those two, and the camera is in the outside one at the Camera directive. A
 * shape whose two are the same is no boundary. clpt's rule is the same
 * (kernels/medium/medium.h), so the state maps directly.
 */
#include "io/pbrt_reader.h"

#include "util/kmath.h"
#include "scene/blackbody.h"
#include "scene/media.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* pbrt-v4's "Le" of a medium (its emitted radiance; 0 when not given) times `scale`.
 * pbrt-v4 divides an RGB illuminant by its illuminant's luminance, which leaves the
 * RGB values themselves as the radiance, as clpt reads them. */
static Status medium_le(Parser *p, const Lexer *lx, const Token *name, vec3 sigma_a, double scale, vec3 *le)
{
    Status st;
    *le = v3s(0.0f);
    if ((st = pbrt_get_spectrum(p, lx, "Le", le, NULL, NULL))) return st;
    if (!(scale >= 0.0) || !(scale <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "Lescale"), "a number in [0, 1e30]");
    *le = v3_scale(*le, (float)scale);
    vec3 e = v3_mul(*le, sigma_a);
    if (!isfinite(le->x) || !isfinite(le->y) || !isfinite(le->z) || !isfinite(e.x) || !isfinite(e.y) ||
        !isfinite(e.z))
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": its emission (Le times Lescale and "
                            "sigma_a) is beyond the largest float (about 3.4e38)",
                            (int)(name->len > 40 ? 40 : name->len), name->text);
    return ST_OK;
}

/* pbrt_reader.h: every medium's sigma_a and sigma_s, times its scale, and g. */
Status pbrt_medium_coefficients(Parser *p, const Lexer *lx, const Token *name, int read_scale, vec3 *sa, vec3 *ss,
                                float *g_out)
{
    Status st;
    vec3 a = v3s(1.0f), s = v3s(1.0f);
    double scale = 1.0, g = 0.0;
    if ((st = pbrt_get_spectrum(p, lx, "sigma_a", &a, NULL, NULL)) ||
        (st = pbrt_get_spectrum(p, lx, "sigma_s", &s, NULL, NULL)) ||
        (read_scale && (st = pbrt_get_float(p, lx, "scale", &scale))) || (st = pbrt_get_float(p, lx, "g", &g)))
        return st;
    if (!(scale >= 0.0) || !(scale <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "scale"), "a number in [0, 1e30]");
    if (!(g > -1.0 && g < 1.0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "g"), "a number in (-1, 1)");
    a = v3_scale(a, (float)scale);
    s = v3_scale(s, (float)scale);
    vec3 t = v3_add(a, s);
    if (!isfinite(t.x) || !isfinite(t.y) || !isfinite(t.z))
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": its extinction (sigma_a + sigma_s, times "
                            "scale) is beyond the largest float (about 3.4e38)", (int)(name->len > 40 ? 40 : name->len), name->text);
    *sa = a;
    *ss = s;
    *g_out = (float)g;
    return ST_OK;
}

/* pbrt_reader.h: a grid's nx ny nz (1 each by default), each >= 1, at most 2^24 cells. */
Status pbrt_medium_grid_size(Parser *p, const Lexer *lx, const Token *name, long n[3], double *cells)
{
    Status st;
    int nlen = (int)(name->len > 40 ? 40 : name->len);
    n[0] = n[1] = n[2] = 1;
    if ((st = pbrt_get_int(p, lx, "nx", &n[0])) || (st = pbrt_get_int(p, lx, "ny", &n[1])) ||
        (st = pbrt_get_int(p, lx, "nz", &n[2])))
        return st;
    *cells = 1.0;
    for (int i = 0; i < 3; i++) {
        if (n[i] < 1)
            return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": nx, ny and nz must be >= 1, found "
                                "%ld %ld %ld", nlen, name->text, n[0], n[1], n[2]);
        *cells *= (double)n[i];
    }
    if (*cells > (double)(1u << 24))
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": a grid of %ld x %ld x %ld cells is more "
                            "than %u", nlen, name->text, n[0], n[1], n[2], 1u << 24);
    return ST_OK;
}

/* pbrt_reader.h: a grid's box p0 p1 (the unit cube by default), p1 above p0 on every axis. */
Status pbrt_medium_box(Parser *p, const Lexer *lx, const Token *name, vec3 *lo, vec3 *hi)
{
    Status st;
    *lo = v3s(0.0f);
    *hi = v3s(1.0f);
    if ((st = pbrt_get_point(p, lx, "p0", lo)) || (st = pbrt_get_point(p, lx, "p1", hi))) return st;
    if (!(lo->x < hi->x && lo->y < hi->y && lo->z < hi->z))
        return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": p1 must be greater than p0 on every "
                            "axis, found p0 %g %g %g, p1 %g %g %g", (int)(name->len > 40 ? 40 : name->len),
                            name->text, (double)lo->x, (double)lo->y, (double)lo->z, (double)hi->x, (double)hi->y,
                            (double)hi->z);
    return ST_OK;
}

/* pbrt-v4's homogeneous medium: sigma_a and sigma_s (1 each by default), times
 * `scale`; `g`; its emission "Le" times "Lescale" (medium_le; the grid reads its own
 * "Lescale", a grid). Its named presets are an error (one would decide the whole
 * look). */
static Status homogeneous(Parser *p, const Lexer *lx, const Token *name, Medium *out)
{
    Status st;
    const Token *preset = NULL;
    if ((st = pbrt_get_string(p, lx, "preset", &preset))) return st;
    if (preset)
        return lex_error_at(lx, preset, p->err, "MakeNamedMedium \"%.*s\": the preset \"%.*s\" is not supported "
                            "(give \"rgb sigma_a\" and \"rgb sigma_s\" instead)", (int)(name->len > 40 ? 40 : name->len),
                            name->text, (int)(preset->len > 40 ? 40 : preset->len), preset->text);
    vec3 sa, ss;
    float g;
    if ((st = pbrt_medium_coefficients(p, lx, name, 1, &sa, &ss, &g))) return st;
    *out = medium_homogeneous(sa, ss, g);
    return ST_OK;
}

/* A grid parameter `key` of nx ny nz floats (x fastest, as pbrt's SampledGrid), each
 * finite and >= 0, copied into a new array *out; `pv` is the parameter as given. */
static Status grid_values(Parser *p, const Lexer *lx, const Token *name, const Param *pv, const char *key,
                          const long n[3], double cells, float **out)
{
    int nlen = (int)(name->len > 40 ? 40 : name->len);
    if (pv->type != PT_FLOAT) return pbrt_param_type_error(p, lx, pv, "floats");
    if ((double)pv->n != cells)
        return lex_error_at(lx, &pv->decl, p->err, "MakeNamedMedium \"%.*s\": nx ny nz %ld %ld %ld are %.0f "
                            "cells, but \"%s\" has %zu values", nlen, name->text, n[0], n[1], n[2], cells, key,
                            pv->n);
    float *v = malloc(pv->n * sizeof(float));
    if (!v) return error_set(p->err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < pv->n; i++) {
        double x = p->pl.nums[pv->first + i];
        if (!(x >= 0.0) || !(x <= 3.4e38)) {
            free(v);
            return lex_error_at(lx, &pv->decl, p->err, "MakeNamedMedium \"%.*s\": %s %g (value %zu) must be a "
                                "finite number >= 0", nlen, name->text, key, x, i);
        }
        v[i] = (float)x;
    }
    *out = v;
    return ST_OK;
}

/* A uniformgrid's "Lescale": nx ny nz emission scales (x fastest, as the density),
 * each finite and >= 0; *out NULL when not given (scale 1 everywhere). */
static Status grid_le_scale(Parser *p, const Lexer *lx, const Token *name, const long n[3], double cells,
                            float **out)
{
    *out = NULL;
    Param *pl = pbrt_param_find(p, "Lescale");
    return pl ? grid_values(p, lx, name, pl, "Lescale", n, cells, out) : ST_OK;
}

/* A uniformgrid's "Le" (times sigma_a, which medium_le checked alone) times every value
 * of its "Lescale" grid, and its densities times them, must stay a float
 * (grid_emission_fits). */
static Status grid_le_check(Parser *p, const Lexer *lx, const Token *name, vec3 le, vec3 sa, const float *density,
                            const float *scale, size_t cells)
{
    size_t top;
    if (grid_emission_fits(density, scale, cells, v3_max_comp(v3_mul(le, sa)), 1.0, &top)) return ST_OK;
    return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": its Lescale grid's %g (value %zu), times Le and "
                        "sigma_a or times the largest density, is beyond the largest float (about 3.4e38)",
                        (int)(name->len > 40 ? 40 : name->len), name->text, (double)scale[top], top);
}

/* pbrt_reader.h: "temperatureoffset" (pbrt-v4's older name "temperaturecutoff" when it
 * is not given; 0 by default) and "temperaturescale" (1), each finite, the scale >= 0. */
Status pbrt_medium_temperature(Parser *p, const Lexer *lx, GridTemperature *how)
{
    Status st;
    double cutoff = 0.0, offset, scale = 1.0;
    if ((st = pbrt_get_float(p, lx, "temperaturecutoff", &cutoff))) return st;
    offset = cutoff;
    if ((st = pbrt_get_float(p, lx, "temperatureoffset", &offset)) ||
        (st = pbrt_get_float(p, lx, "temperaturescale", &scale)))
        return st;
    if (!(fabs(cutoff) <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "temperaturecutoff"), "a number in [-1e30, 1e30]");
    if (!(fabs(offset) <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "temperatureoffset"), "a number in [-1e30, 1e30]");
    if (!(scale >= 0.0) || !(scale <= 1e30))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "temperaturescale"), "a number in [0, 1e30]");
    how->offset = offset;
    how->scale = scale;
    return ST_OK;
}

/* pbrt_reader.h: sigma_a times the largest emission scale times a blackbody's colour
 * (at most BLACKBODY_RGB_MAX) must stay a float. */
Status pbrt_medium_glow_check(Parser *p, const Lexer *lx, const Token *name, vec3 sa, double scale)
{
    double e = (double)v3_max_comp(sa) * scale * BLACKBODY_RGB_MAX;
    if (e <= 3.4e38) return ST_OK;
    return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": its emission (Lescale times sigma_a and a "
                        "blackbody's colour, up to 256) is beyond the largest float (about 3.4e38)",
                        (int)(name->len > 40 ? 40 : name->len), name->text);
}

/* pbrt-v4's "uniformgrid" medium: "float density" of nx ny nz values (x fastest, as
 * pbrt's SampledGrid) over the box p0 p1 of the medium's space, which the current
 * transform places; sigma_a, sigma_s (1 each by default) times `scale` per unit of
 * density; `g`. pbrt's grid is zero outside its samples' centres' half cell at the
 * border where clpt's clamps to the outermost value (docs/media.md). Its emission:
 * "Le" times the "Lescale" grid, or a "temperature" grid of nx ny nz values, each
 * cell's blackbody times the "Lescale" grid (pbrt-v4's GridMedium; the two are
 * exclusive, as in pbrt). clpt bakes each cell's blackbody colour where pbrt
 * interpolates the temperature (docs/media.md, "Blackbody emission"). */
static Status uniform_grid(Parser *p, const Lexer *lx, const Token *name, Medium *out)
{
    Status st;
    int nlen = (int)(name->len > 40 ? 40 : name->len);
    Medium base;
    if ((st = homogeneous(p, lx, name, &base))) return st;
    long n[3];
    double cells;
    if ((st = pbrt_medium_grid_size(p, lx, name, n, &cells))) return st;
    Param *pd = pbrt_param_find(p, "density");
    if (!pd) return lex_error_at(lx, name, p->err, "MakeNamedMedium \"%.*s\": a \"uniformgrid\" needs \"float "
                                 "density\"", nlen, name->text);
    float *d;
    if ((st = grid_values(p, lx, name, pd, "density", n, cells, &d))) return st;
    vec3 lo, hi;
    if ((st = pbrt_medium_box(p, lx, name, &lo, &hi))) {
        free(d);
        return st;
    }
    vec3 le;
    float *le_scale = NULL, *temperature = NULL;
    GridTemperature how;
    Param *pt = pbrt_param_find(p, "temperature"), *ple = pbrt_param_find(p, "Le");
    if (pt && ple)
        st = lex_error_at(lx, &ple->decl, p->err, "MakeNamedMedium \"%.*s\": a \"uniformgrid\" has \"Le\" or "
                          "\"temperature\", not both", nlen, name->text);
    else if (pt && !(st = grid_values(p, lx, name, pt, "temperature", n, cells, &temperature)))
        st = pbrt_medium_temperature(p, lx, &how);
    if (st || (st = medium_le(p, lx, name, base.sigma_a, 1.0, &le)) ||
        (st = grid_le_scale(p, lx, name, n, cells, &le_scale))) {
        free(d);
        free(temperature);
        return st;
    }
    if (!temperature && le_scale && (st = grid_le_check(p, lx, name, le, base.sigma_a, d, le_scale, (size_t)cells))) {
        free(d);
        free(le_scale);
        return st;
    }
    if (temperature) {
        le = v3s(1.0f);   /* the blackbody alone, times the Lescale grid */
        double top = 1.0;
        for (size_t i = 0; le_scale && i < (size_t)cells; i++) top = le_scale[i] > top ? le_scale[i] : top;
        if ((st = pbrt_medium_glow_check(p, lx, name, base.sigma_a, top))) {
            free(d);
            free(temperature);
            free(le_scale);
            return st;
        }
    }
    uint grid;
    st = scene_add_grid(p->s, d, (uint)n[0], (uint)n[1], (uint)n[2], lo, hi, &p->g.ctm, &grid, p->err);
    free(d);
    if (!st && le_scale && !v3_is_zero(le)) st = scene_grid_set_emission(p->s, grid, le_scale, p->err);
    if (!st && temperature) st = scene_grid_set_temperature(p->s, grid, temperature, how, p->err);
    free(le_scale);
    free(temperature);
    if (st) return st;
    *out = medium_with_emission(medium_grid(base.sigma_a, base.sigma_s, base.g, grid), le);
    return ST_OK;
}

Status pbrt_make_named_medium(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token name;
    Status st = pbrt_expect_head(p, lx, "a quoted medium name", &name);
    if (st) return st;
    if (name.len == 0) return lex_error_at(lx, &name, p->err, "a medium needs a name (\"\" is vacuum)");
    const Token *type = NULL;
    if ((st = pbrt_get_string(p, lx, "type", &type))) return st;
    if (!type) return lex_error_at(lx, &name, p->err, "MakeNamedMedium needs \"string type\"");
    uint32_t ref = 0u;   /* vacuum, for a medium clpt cannot render */
    int grid = pbrt_tok_eq(type, "uniformgrid"), volume = pbrt_volume_type(type);
    if (pbrt_tok_eq(type, "homogeneous") || grid || volume) {
        Medium m;
        if ((st = volume ? pbrt_volume_medium(p, lx, &name, type, &m)
                  : grid ? uniform_grid(p, lx, &name, &m) : homogeneous(p, lx, &name, &m)))
            return st;
        if (!grid && !volume) {
            double le_scale = 1.0;
            vec3 le;
            if ((st = pbrt_get_float(p, lx, "Lescale", &le_scale)) ||
                (st = medium_le(p, lx, &name, m.sigma_a, le_scale, &le)))
                return st;
            m = medium_with_emission(m, le);
        }
        char *n = tok_copy(&name);
        if (!n) return error_set(p->err, ST_INTERNAL, "out of memory");
        uint index;
        st = scene_add_medium(p->s, n, m, &index, p->err);
        free(n);
        if (st) return st;
        ref = index + 1u;
        char what[64];
        snprintf(what, sizeof what, "MakeNamedMedium \"%.*s\"", (int)(type->len > 40 ? 40 : type->len), type->text);
        if ((st = pbrt_warn_unused(p, lx, what))) return st;
    } else {
        char key[96];
        snprintf(key, sizeof key, "Medium %.*s", (int)(type->len > 40 ? 40 : type->len), type->text);
        for (size_t i = 0; i < p->pl.n; i++) p->pl.p[i].used = 1;
        if ((st = warn_once(p, lx, type, key, "medium \"%.*s\" is not supported; \"%.*s\" is left empty (vacuum)",
                            (int)(type->len > 40 ? 40 : type->len), type->text, (int)(name.len > 40 ? 40 : name.len),
                            name.text)))
            return st;
    }
    /* a later definition of the name replaces the earlier, as in pbrt */
    if (strmap_set(&p->named_medium, name.text, name.len, ref)) return error_set(p->err, ST_INTERNAL, "out of memory");
    return ST_OK;
}

/* A medium name of MediumInterface: "" is vacuum, any other must be defined. */
static Status medium_ref(Parser *p, const Lexer *lx, const Token *t, uint *ref)
{
    uint32_t r;
    if (t->len == 0) {
        *ref = 0u;
        return ST_OK;
    }
    if (!strmap_find(&p->named_medium, t->text, t->len, &r))
        return lex_error_at(lx, t, p->err, "medium '%.*s' is not defined (MakeNamedMedium defines it)",
                            (int)(t->len > 40 ? 40 : t->len), t->text);
    *ref = r;
    return ST_OK;
}

Status pbrt_medium_interface(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token in, out;
    Status st = pbrt_expect_string(p, lx, "a quoted medium name (\"\" for vacuum)", &in);
    if (st) return st;
    if ((st = lex_next(lx, &out, p->err))) return st;
    if (out.kind != TOK_STRING) {   /* one name: both sides */
        lex_unread(lx, &out);
        out = in;
    }
    uint ri, ro;
    if ((st = medium_ref(p, lx, &in, &ri)) || (st = medium_ref(p, lx, &out, &ro))) return st;
    p->g.medium_in = ri;
    p->g.medium_out = ro;
    return ST_OK;
}

Status pbrt_shape_media(Parser *p, uint material, uint *out)
{
    if (p->g.medium_in == p->g.medium_out) {
        *out = material;
        return ST_OK;
    }
    return scene_bind_media(p->s, material, p->g.medium_in, p->g.medium_out, out, p->err);
}
