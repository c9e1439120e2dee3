/* gltf_material.c — glTF materials, textures and samplers (gltf_reader.h, docs/gltf.md). */
#include "io/gltf_reader.h"

#include "base/bytes.h"
#include "base/limit.h"
#include "base/strmap.h"
#include "io/lexer.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "scene/subsurface.h"
#include "util/kmath.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cjson/cJSON.h>


/* ------------------------------------------------------------------ materials */

/* The scene texture of textures[t] in the given encoding, read once. */
static Status texture_get(Gltf *g, int t, int linear, const char *jpath, uint *out)
{
    const cJSON *tex = gltf_item_at(g, "textures", t);
    char jp[64];
    snprintf(jp, sizeof jp, "textures[%d]", t);
    int img;
    Status st = gltf_get_index(g, tex, "source", 1, "images", jp, &img);
    if (st) return st;
    uint *slot = &g->tex[2 * img + (linear ? 1 : 0)];
    if (*slot != NO_INDEX) {
        *out = *slot;
        return ST_OK;
    }
    const cJSON *im = gltf_item_at(g, "images", img);
    char ji[64], src[1200];
    snprintf(ji, sizeof ji, "images[%d]", img);
    snprintf(src, sizeof src, "%s: %s (for %s)", g->path, ji, jpath);
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(im, "uri");
    int view;
    if ((st = gltf_get_index(g, im, "bufferView", 0, "bufferViews", ji, &view))) return st;
    /* images with one source (a file, a data: URI, a buffer view) share one decode of
     * it: a 20 KB GLB whose hundreds of images named one buffer view decoded it for each,
     * 2.1 GB in all (issue 39) */
    char *file = NULL;
    if (cJSON_IsString(uri) && strncmp(uri->valuestring, "data:", 5) != 0 &&
        (st = gltf_uri_file(g, uri->valuestring, ji, &file)))
        return st;
    /* a buffer view's key starts with a NUL, which no file name or URI holds */
    char view_key[24] = { 0 };
    size_t key_len = 1 + (size_t)snprintf(view_key + 1, sizeof view_key - 1, "view %d", view);
    const char *key = view_key;
    if (file || cJSON_IsString(uri)) {
        key = file ? file : uri->valuestring;
        key_len = strlen(key);
    }
    StrMap *known = &g->image_sources[linear ? 1 : 0];
    uint32_t shared;
    if ((cJSON_IsString(uri) || view >= 0) && strmap_find(known, key, key_len, &shared)) {
        free(file);
        *slot = *out = shared;
        return ST_OK;
    }
    if (file) {
        st = texture_load_image(g->s, NULL, file, linear, 0, slot, g->err);
        if (st) reader_annotate_json(g->path, ji, g->err);
    } else if (cJSON_IsString(uri)) {
        Buf b = { NULL, 0, 0, NULL };
        if (!(st = gltf_uri_read(g, uri->valuestring, ji, &b)))
            st = texture_load_image_memory(g->s, NULL, src, b.p, b.len, linear, slot, g->err);
        free(b.owned);
    } else if (view >= 0) {
        Buf b;
        size_t stride;
        if (!(st = gltf_view_bytes(g, view, &b, &stride)))
            st = texture_load_image_memory(g->s, NULL, src, b.p, b.len, linear, slot, g->err);
    } else {
        return gltf_bad(g, ji, "has neither a uri nor a bufferView");
    }
    if (!st && strmap_add(known, key, key_len, *slot) < 0) st = error_set(g->err, ST_INTERNAL, "out of memory");
    free(file);
    if (!st) *out = *slot;
    return st;
}

/* KHR_texture_transform's map: glTF's uv' = T R S uv, its rotation matrix
 * [cos -sin; sin cos] as the extension's shader writes it, taken between clpt's (u, v)
 * and glTF's (u, 1 - v) on both sides; its texCoord, when it has one, replaces *tc. */
static Status texture_transform(Gltf *g, const cJSON *tt, const char *jpath, float m[12], long long *tc)
{
    char jp[340];
    snprintf(jp, sizeof jp, "%s.extensions.KHR_texture_transform", jpath);
    static const double zero2[2] = { 0, 0 }, one2[2] = { 1, 1 };
    double off[2], sc[2], rot;
    Status st = gltf_get_nums(g, tt, "offset", 2, zero2, jp, off);
    if (!st) st = gltf_get_nums(g, tt, "scale", 2, one2, jp, sc);
    if (!st) st = gltf_get_num(g, tt, "rotation", 0.0, -1e6, 1e6, jp, &rot);
    if (!st) st = gltf_get_int(g, tt, "texCoord", *tc, 0, 64, jp, tc);
    if (st) return st;
    double a = sc[0] * cos(rot), b = -sc[1] * sin(rot), c = sc[0] * sin(rot), d = sc[1] * cos(rot);
    const float mm[12] = { (float)a, (float)-b, 0.0f, (float)(b + off[0]),
                           (float)-c, (float)d, 0.0f, (float)(1.0 - d - off[1]),
                           0.0f, 0.0f, 1.0f, 0.0f };
    memcpy(m, mm, sizeof mm);
    Texture t;
    memcpy(t.m, mm, sizeof mm);
    st = texture_check_map(&t, g->err);
    if (st) reader_annotate_json(g->path, jp, g->err);
    return st;
}

/* One axis of a sampler: glTF's REPEAT, CLAMP_TO_EDGE or MIRRORED_REPEAT. */
static Status sampler_wrap(Gltf *g, const cJSON *smp, const char *key, const char *jp, uint clamp, uint mirror,
                           uint *flags)
{
    long long w;
    Status st = gltf_get_int(g, smp, key, 10497, 0, 65535, jp, &w);
    if (st) return st;
    if (w == 33071) *flags |= clamp;
    else if (w == 33648) *flags |= mirror;
    else if (w != 10497)
        return error_set(g->err, ST_INPUT, "%s: %s.%s: expected 10497 (REPEAT), 33071 (CLAMP_TO_EDGE) or 33648 "
                         "(MIRRORED_REPEAT)", g->path, jp, key);
    return ST_OK;
}

/* The TEX_* sampling flags of textures[t]'s sampler: wrapS (u) and wrapT (v), and
 * magFilter NEAREST. clpt has no mip-maps, so one filter serves every lookup: the
 * magnification filter's; minFilter is ignored. */
static Status sampler_flags(Gltf *g, int t, uint *flags)
{
    *flags = 0;
    char jt[64];
    snprintf(jt, sizeof jt, "textures[%d]", t);
    int si;
    Status st = gltf_get_index(g, gltf_item_at(g, "textures", t), "sampler", 0, "samplers", jt, &si);
    if (st || si < 0) return st;
    const cJSON *smp = gltf_item_at(g, "samplers", si);
    char jp[64];
    snprintf(jp, sizeof jp, "samplers[%d]", si);
    long long mag;
    if ((st = sampler_wrap(g, smp, "wrapS", jp, TEX_CLAMP_U, TEX_MIRROR_U, flags)) ||
        (st = sampler_wrap(g, smp, "wrapT", jp, TEX_CLAMP_V, TEX_MIRROR_V, flags)) ||
        (st = gltf_get_int(g, smp, "magFilter", 9729, 0, 65535, jp, &mag)))
        return st;
    if (mag == 9728) *flags |= TEX_NEAREST;
    else if (mag != 9729)
        return error_set(g->err, ST_INPUT, "%s: %s.magFilter: expected 9728 (NEAREST) or 9729 (LINEAR)", g->path, jp);
    return ST_OK;
}

/* The texture a textureInfo object at obj.key names, or NO_INDEX: the image's texture,
 * or a copy of it (a texture record of its own over the same texels) with its sampler's
 * wrap and filter flags, TEX_UV1 for texCoord 1 and KHR_texture_transform's map. */
static Status texinfo(Gltf *g, const cJSON *obj, const char *key, int linear, const char *jpath, uint *out,
                      double *scale)
{
    const cJSON *ti = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = NO_INDEX;
    if (!ti) return ST_OK;
    char jp[300];
    snprintf(jp, sizeof jp, "%s.%s", jpath, key);
    int t;
    long long tc;
    uint flags;
    float m[12];
    const cJSON *tt = gltf_ext_of(ti, "KHR_texture_transform");
    Status st = gltf_get_index(g, ti, "index", 1, "textures", jp, &t);
    if (!st) st = gltf_get_int(g, ti, "texCoord", 0, 0, 64, jp, &tc);
    if (!st && scale) st = gltf_get_num(g, ti, "scale", 1.0, -1e6, 1e6, jp, scale);
    if (!st && tt) st = texture_transform(g, tt, jp, m, &tc);
    if (!st) st = sampler_flags(g, t, &flags);
    if (st) return st;
    if (tc > 1 && (st = scene_warn(g->s, g->err, "%s: %s: texCoord %lld is read as TEXCOORD_0 (clpt reads "
                                   "TEXCOORD_0 and TEXCOORD_1)", g->path, jp, tc)))
        return st;
    if (tc == 1) flags |= TEX_UV1;
    if ((st = texture_get(g, t, linear, jp, out))) return st;
    if (!flags && !tt) return ST_OK;
    Texture tx = g->s->textures[*out];
    tx.flags |= flags;
    if (tt) texture_set_matrix(&tx, m);
    return scene_add_texture(g->s, NULL, NULL, tx, out, g->err);
}

/* A copy of texture `base` with every texel multiplied by `factor` (glTF's base colour
 * is texture x baseColorFactor; clpt's texture replaces the albedo), its texels linear
 * floats so that the product is exact and filtered as the original would be. */
static Status texture_tinted(Gltf *g, uint base, const double factor[3], uint *out)
{
    Texture t = g->s->textures[base];
    size_t n = (size_t)t.width * t.height;
    uint *texels = malloc(3 * n * sizeof *texels + 1);
    if (!texels) return error_set(g->err, ST_INTERNAL, "out of memory tinting a texture");
    for (size_t i = 0; i < n; i++) {
        float rgb[3];
        if (t.flags & TEX_FLOAT) {
            memcpy(rgb, g->s->texels + t.offset + 3 * i, sizeof rgb);
        } else {
            uint c = g->s->texels[t.offset + i];
            for (int k = 0; k < 3; k++) {
                rgb[k] = (float)((c >> (8 * k)) & 255u) / 255.0f;
                if (t.flags & TEX_SRGB) rgb[k] = k_srgb_to_linear(rgb[k]);
            }
        }
        for (int k = 0; k < 3; k++) {
            float v = rgb[k] * (float)factor[k];
            memcpy(&texels[3 * i + (size_t)k], &v, sizeof v);
        }
    }
    uint offset;
    Status st = scene_add_texels(g->s, texels, 3 * n, &offset, g->err);
    free(texels);
    if (st) return st;
    t.offset = offset;
    t.flags = (t.flags & TEX_SAMPLING) | TEX_FLOAT;
    return scene_add_texture(g->s, NULL, NULL, t, out, g->err);
}

/* alphaMode OPAQUE (the default: alpha ignored), MASK (cut out where alpha, baseColorFactor's
 * A times the base-colour texture's alpha, is below alphaCutoff, default 0.5) or BLEND
 * (a hit kept with probability alpha, kernels/accel/alpha.h). */
static Status material_alpha(Gltf *g, const cJSON *m, const char *jp, double alpha, Material *mt)
{
    char jpa[96];
    snprintf(jpa, sizeof jpa, "%s.alphaMode", jp);
    const cJSON *mode = cJSON_GetObjectItemCaseSensitive(m, "alphaMode");
    mt->alpha = (float)alpha;
    if (!mode) return ST_OK;
    if (!cJSON_IsString(mode)) return gltf_bad(g, jpa, "expected \"OPAQUE\", \"MASK\" or \"BLEND\"");
    if (strcmp(mode->valuestring, "MASK") == 0) {
        double cutoff;
        Status st = gltf_get_num(g, m, "alphaCutoff", 0.5, 0.0, 1.0, jp, &cutoff);
        if (st) return st;
        mt->alpha_cutoff = (float)cutoff;
        mt->flags |= MAT_ALPHA_MASK;
    } else if (strcmp(mode->valuestring, "BLEND") == 0) {
        mt->flags |= MAT_ALPHA_BLEND;
    } else if (strcmp(mode->valuestring, "OPAQUE") != 0) {
        return gltf_bad(g, jpa, "expected \"OPAQUE\", \"MASK\" or \"BLEND\"");
    }
    return ST_OK;
}

/* The defaults of the extensions' colour factors. */
static const double white3[3] = { 1, 1, 1 }, black3[3] = { 0, 0, 0 };

/* A colour read as doubles, as the renderer's floats. */
static vec3 v3_of_doubles(const double c[3]) { return v3((float)c[0], (float)c[1], (float)c[2]); }

/* The material m's extension `name`, or NULL; where it is there, its JSON path (below
 * m's, jp) into jx, for the messages about its keys. */
static const cJSON *material_ext(const cJSON *m, const char *name, const char *jp, char *jx, size_t jx_size)
{
    const cJSON *x = gltf_ext_of(m, name);
    if (x) snprintf(jx, jx_size, "%s.extensions.%s", jp, name);
    return x;
}

/* KHR_materials_volume: thicknessFactor > 0 makes the mesh the boundary of a solid (a
 * path tracer has the real thickness, so neither the factor's value nor thicknessTexture
 * is read), inside which attenuationColor / attenuationDistance absorb (Beer-Lambert,
 * kernels/integrator/shade_path.h). Thickness 0, the default, keeps the thin wall. */
static Status material_volume(Gltf *g, const cJSON *m, const char *jp, Material *mt)
{
    char jx[128];
    const cJSON *x = material_ext(m, "KHR_materials_volume", jp, jx, sizeof jx);
    if (!x) return ST_OK;
    double thickness, distance, color[3];
    Status st = gltf_get_num(g, x, "thicknessFactor", 0.0, 0.0, 1e30, jx, &thickness);
    if (!st) st = gltf_get_num(g, x, "attenuationDistance", INFINITY, 1e-30, INFINITY, jx, &distance);
    if (!st) st = gltf_get_nums(g, x, "attenuationColor", 3, white3, jx, color);
    if (st) return st;
    if (!(thickness > 0.0)) return ST_OK;
    mt->flags &= ~MAT_THIN;
    mt->absorption = material_absorption(v3_of_doubles(color), (float)distance);
    return ST_OK;
}

/* An extension that is a factor in [0, 1] and a colour factor, each times a texture of
 * its own (the factor's by the texture's alpha, linear; the colour's sRGB): the shape
 * KHR_materials_specular, _sheen and _diffuse_transmission share. */
typedef struct {
    const char *name;                        /* the extension */
    const char *factor, *factor_texture;     /* its keys ... */
    const char *color, *color_texture;
    double factor_default;                   /* ... and their defaults */
    const double *color_default;
    int color_in_unit;                       /* each colour component must lie in [0, 1] */
} FactorColorExt;

/* Material m's extension e, where it is there: the factor into *factor, the colour into
 * *color and the two textures' indices, and the factor as read into *factor_read (0
 * where the extension is absent; NULL: not wanted). Nothing but the textures is written
 * unless all of it reads. */
static Status factor_color_ext(Gltf *g, const cJSON *m, const char *jp, const FactorColorExt *e, float *factor,
                               vec3 *color, uint *factor_texture, uint *color_texture, double *factor_read)
{
    char jx[128];
    if (factor_read) *factor_read = 0.0;
    const cJSON *x = material_ext(m, e->name, jp, jx, sizeof jx);
    if (!x) return ST_OK;
    double f, c[3];
    Status st = gltf_get_num(g, x, e->factor, e->factor_default, 0.0, 1.0, jx, &f);
    if (!st) st = gltf_get_nums(g, x, e->color, 3, e->color_default, jx, c);
    for (int k = 0; !st && e->color_in_unit && k < 3; k++)
        if (!(c[k] >= 0.0 && c[k] <= 1.0))
            st = error_set(g->err, ST_INPUT, "%s: %s.%s[%d]: expected a number from 0 to 1", g->path, jx, e->color, k);
    if (!st) st = texinfo(g, x, e->factor_texture, 1, jx, factor_texture, NULL);
    if (!st) st = texinfo(g, x, e->color_texture, 0, jx, color_texture, NULL);
    if (st) return st;
    *factor = (float)f;
    *color = v3_of_doubles(c);
    if (factor_read) *factor_read = f;
    return ST_OK;
}

/* KHR_materials_specular: specularFactor (times specularTexture's alpha) and
 * specularColorFactor (times specularColorTexture, sRGB) scale the dielectric F0 and
 * F90 (kernels/bsdf/principled.h). */
static Status material_specular(Gltf *g, const cJSON *m, const char *jp, Material *mt)
{
    static const FactorColorExt e = { "KHR_materials_specular", "specularFactor", "specularTexture",
                                      "specularColorFactor", "specularColorTexture", 1.0, white3, 0 };
    return factor_color_ext(g, m, jp, &e, &mt->specular_factor, &mt->specular_color, &mt->texture_specular,
                            &mt->texture_specular_color, NULL);
}

/* KHR_materials_sheen: sheenColorFactor (times sheenColorTexture, sRGB) and
 * sheenRoughnessFactor (times sheenRoughnessTexture's alpha). */
static Status material_sheen(Gltf *g, const cJSON *m, const char *jp, Material *mt)
{
    static const FactorColorExt e = { "KHR_materials_sheen", "sheenRoughnessFactor", "sheenRoughnessTexture",
                                      "sheenColorFactor", "sheenColorTexture", 0.0, black3, 0 };
    return factor_color_ext(g, m, jp, &e, &mt->sheen_roughness, &mt->sheen_color, &mt->texture_sheen_roughness,
                            &mt->texture_sheen_color, NULL);
}

/* KHR_materials_diffuse_transmission: diffuseTransmissionFactor (times
 * diffuseTransmissionTexture's alpha) of the diffuse layer passes to the back side,
 * tinted by diffuseTransmissionColorFactor (times diffuseTransmissionColorTexture,
 * sRGB): the principled material's Lambertian transmission (kernels/bsdf/principled.h).
 * Without KHR_materials_volume the surface is the spec's thin wall; the volume, read
 * after, makes it a solid. Each colour component must lie in [0, 1], as the spec says. */
static Status material_diffuse_transmission(Gltf *g, const cJSON *m, const char *jp, Material *mt)
{
    static const FactorColorExt e = { "KHR_materials_diffuse_transmission", "diffuseTransmissionFactor",
                                      "diffuseTransmissionTexture", "diffuseTransmissionColorFactor",
                                      "diffuseTransmissionColorTexture", 0.0, white3, 1 };
    double factor;
    Status st = factor_color_ext(g, m, jp, &e, &mt->diffuse_transmission, &mt->diffuse_transmission_color,
                                 &mt->texture_diffuse_transmission, &mt->texture_diffuse_transmission_color, &factor);
    if (!st && factor > 0.0) mt->flags |= MAT_THIN;
    return st;
}

/* The single-scattering albedo of the multiple-scattering albedo ms in [0, 1]:
 * KHR_materials_volume_scatter's inversion (after Kulla and Conty 2017, "Revisiting
 * Physically Based Shading at Imageworks"), 0 at 0 and 1 at 1. */
static double volume_single_albedo(double ms)
{
    double r = 4.09712 + 4.20863 * ms - sqrt(9.59217 + 41.6808 * ms + 17.7126 * ms * ms);
    double ss = 1.0 - r * r;
    return ss < 0.0 ? 0.0 : (ss > 1.0 ? 1.0 : ss);
}

/* KHR_materials_volume_scatter, after KHR_materials_volume and _diffuse_transmission:
 * the solid's interior scatters. The extension's non-normative mapping: sigma_t =
 * -ln(attenuationColor) / attenuationDistance (absorption and scattering together now),
 * sigma_s = rho_ss sigma_t with rho_ss from multiscatterColor (volume_single_albedo),
 * sigma_a the rest, Henyey-Greenstein g = scatterAnisotropy. clpt walks it as a
 * subsurface medium (docs/subsurface.md): the diffuse transmission's share becomes the
 * `subsurface` weight (what enters the volume diffusely; a walk leaves it as a
 * Lambertian transmission, the extension's BTDF), the Beer-Lambert absorption is
 * dropped (the medium absorbs), and diffuseTransmissionColor is not used. Without a
 * solid, an attenuation or a diffuse transmission no light would scatter inside, so
 * the extension is then ignored with a warning. */
static Status material_volume_scatter(Gltf *g, const cJSON *m, const char *jp, const char *name, Material *mt)
{
    char jx[128];
    const cJSON *x = material_ext(m, "KHR_materials_volume_scatter", jp, jx, sizeof jx);
    if (!x) return ST_OK;
    double ms[3], aniso;
    Status st = gltf_get_nums(g, x, "multiscatterColor", 3, black3, jx, ms);
    for (int k = 0; !st && k < 3; k++)
        if (!(ms[k] >= 0.0 && ms[k] <= 1.0))
            st = error_set(g->err, ST_INPUT, "%s: %s.multiscatterColor[%d]: expected a number from 0 to 1", g->path,
                           jx, k);
    if (!st) st = gltf_get_num(g, x, "scatterAnisotropy", 0.0, -1.0, 1.0, jx, &aniso);
    if (!st && (aniso <= -1.0 || aniso >= 1.0))
        st = error_set(g->err, ST_INPUT, "%s: %s.scatterAnisotropy: expected a number between -1 and 1, both "
                       "excluded", g->path, jx);
    if (st) return st;
    vec3 sigma_t = mt->absorption;
    const char *why = (mt->flags & MAT_THIN) ? "KHR_materials_volume with thicknessFactor > 0"
                      : !(sigma_t.x > 0.0f || sigma_t.y > 0.0f || sigma_t.z > 0.0f)
                          ? "KHR_materials_volume's attenuationDistance and attenuationColor"
                      : !(mt->diffuse_transmission > 0.0f) ? "KHR_materials_diffuse_transmission"
                                                           : NULL;
    if (why)
        return scene_warn(g->s, g->err, "%s: %s: ignored: nothing scatters inside without %s", g->path, jx, why);
    double t[3] = { sigma_t.x, sigma_t.y, sigma_t.z }, sa[3], ss[3];
    for (int k = 0; k < 3; k++) {
        ss[k] = t[k] * volume_single_albedo(ms[k]);
        sa[k] = t[k] - ss[k];
        if (sa[k] < 0.0) sa[k] = 0.0;
    }
    float weight = mt->diffuse_transmission;
    mt->diffuse_transmission = 0.0f;
    mt->texture_diffuse_transmission = mt->texture_diffuse_transmission_color = NO_INDEX;
    mt->absorption = v3s(0.0f);
    return scene_add_subsurface(g->s, mt, name, weight, v3_of_doubles(sa), v3_of_doubles(ss), (float)aniso, g->err);
}

static Status material_build(Gltf *g, int i, uint *out)
{
    char jp[64];
    snprintf(jp, sizeof jp, "materials[%d]", i);
    const cJSON *m = gltf_item_at(g, "materials", i);
    const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(m, "pbrMetallicRoughness");
    char jpp[96];
    snprintf(jpp, sizeof jpp, "%s.pbrMetallicRoughness", jp);
    static const double ones[4] = { 1, 1, 1, 1 }, zeros[3] = { 0, 0, 0 };
    double base[4], metallic, rough, emit[3], strength = 1.0, nscale = 1.0;
    Status st = gltf_get_nums(g, pbr, "baseColorFactor", 4, ones, jpp, base);
    if (!st) st = gltf_get_num(g, pbr, "metallicFactor", 1.0, 0.0, 1.0, jpp, &metallic);
    if (!st) st = gltf_get_num(g, pbr, "roughnessFactor", 1.0, 0.0, 1.0, jpp, &rough);
    if (!st) st = gltf_get_nums(g, m, "emissiveFactor", 3, zeros, jp, emit);
    const cJSON *es = gltf_ext_of(m, "KHR_materials_emissive_strength");
    if (!st && es) st = gltf_get_num(g, es, "emissiveStrength", 1.0, 0.0, 1e30, jp, &strength);
    if (st) return st;
    Material mt = material_principled(v3_of_doubles(base), (float)metallic,
                                      (float)rough);
    mt.emission = v3((float)(emit[0] * strength), (float)(emit[1] * strength), (float)(emit[2] * strength));
    if (emit[0] > 0 || emit[1] > 0 || emit[2] > 0) g->has_lights = 1;
    if (cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(m, "doubleSided"))) mt.flags |= MAT_TWO_SIDED;
    if ((st = texinfo(g, pbr, "baseColorTexture", 0, jpp, &mt.texture, NULL))) return st;
    if (mt.texture != NO_INDEX && (base[0] != 1 || base[1] != 1 || base[2] != 1) &&
        (st = texture_tinted(g, mt.texture, base, &mt.texture)))
        return st;
    if ((st = texinfo(g, pbr, "metallicRoughnessTexture", 1, jpp, &mt.texture_rm, NULL))) return st;
    if ((st = texinfo(g, m, "normalTexture", 1, jp, &mt.texture_normal, &nscale))) return st;
    mt.normal_scale = (float)nscale;
    /* the emissive texture is sRGB-encoded, like the base colour (glTF 2.0, 3.9.5) */
    if ((st = texinfo(g, m, "emissiveTexture", 0, jp, &mt.texture_emission, NULL))) return st;
    if ((st = material_alpha(g, m, jp, base[3], &mt))) return st;
    double v;
    const cJSON *x;
    if ((x = gltf_ext_of(m, "KHR_materials_ior"))) {
        if ((st = gltf_get_num(g, x, "ior", 1.5, 1.0, 10.0, jp, &v))) return st;
        mt.ior = (float)v;
    }
    if ((x = gltf_ext_of(m, "KHR_materials_transmission"))) {
        if ((st = gltf_get_num(g, x, "transmissionFactor", 0.0, 0.0, 1.0, jp, &v))) return st;
        mt.transmission = (float)v;
        mt.flags |= MAT_THIN;   /* without KHR_materials_volume a glTF surface is a thin wall */
    }
    if ((x = gltf_ext_of(m, "KHR_materials_clearcoat"))) {
        if ((st = gltf_get_num(g, x, "clearcoatFactor", 0.0, 0.0, 1.0, jp, &v))) return st;
        mt.clearcoat = (float)v;
        if ((st = gltf_get_num(g, x, "clearcoatRoughnessFactor", 0.0, 0.0, 1.0, jp, &v))) return st;
        mt.clearcoat_roughness = (float)v;
    }
    if ((st = material_diffuse_transmission(g, m, jp, &mt)) || (st = material_volume(g, m, jp, &mt)) ||
        (st = material_specular(g, m, jp, &mt)) ||
        (st = material_sheen(g, m, jp, &mt)))
        return st;
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(m, "name");
    const char *mname = cJSON_IsString(name) ? name->valuestring : "";
    if ((st = material_volume_scatter(g, m, jp, mname, &mt))) return st;
    return scene_add_material(g->s, mname, mt, out, g->err);
}

Status gltf_material_get(Gltf *g, int i, uint *out)
{
    if (g->o->material != NO_INDEX) {
        *out = g->o->material;
        return ST_OK;
    }
    uint *slot = i < 0 ? &g->default_mat : &g->mats[i];
    if (*slot == NO_INDEX) {
        /* glTF's default material: white, metallic 1, roughness 1 */
        Status st = i < 0 ? scene_add_material(g->s, "", material_principled(v3s(1.0f), 1.0f, 1.0f), slot, g->err)
                          : material_build(g, i, slot);
        if (st) return st;
    }
    *out = *slot;
    return ST_OK;
}
