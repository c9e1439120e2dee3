/*
 * scene_material.c — the scene reader's materials (their keys, and which keys each type
 * takes) and textures; part of the reader of scene_parse.c (scene_reader.h).
 */
#include "io/scene_reader.h"

#include "base/array.h"
#include "util/kmath.h"
#include "io/lexer.h"
#include "io/reader.h"
#include "io/texture.h"
#include "scene/subsurface.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAT_KEY_TYPE, MAT_KEY_ALBEDO, MAT_KEY_FUZZ, MAT_KEY_IOR, MAT_KEY_RADIANCE, MAT_KEY_EMISSION, MAT_KEY_SIDES,
       MAT_KEY_SPECULAR, MAT_KEY_SHININESS, MAT_KEY_REFLECTIVE, MAT_KEY_TRANSPARENT, MAT_KEY_TEXTURE,
       MAT_KEY_ROUGHNESS, MAT_KEY_ANISOTROPY, MAT_KEY_ETA, MAT_KEY_K, MAT_KEY_METAL, MAT_KEY_THIN,
       MAT_KEY_METALLIC, MAT_KEY_TRANSMISSION, MAT_KEY_CLEARCOAT, MAT_KEY_CLEARCOAT_ROUGHNESS, MAT_KEY_STRENGTH,
       MAT_KEY_METALLIC_ROUGHNESS, MAT_KEY_NORMAL_MAP, MAT_KEY_NORMAL_SCALE, MAT_KEY_ALPHA, MAT_KEY_ALPHA_MODE,
       MAT_KEY_ALPHA_CUTOFF, MAT_KEY_EMISSION_TEXTURE, MAT_KEY_ATTENUATION_COLOR, MAT_KEY_ATTENUATION_DISTANCE,
       MAT_KEY_SPECULAR_FACTOR, MAT_KEY_SPECULAR_COLOR, MAT_KEY_SHEEN_COLOR, MAT_KEY_SHEEN_ROUGHNESS,
       MAT_KEY_SUBSURFACE, MAT_KEY_SUBSURFACE_COLOR, MAT_KEY_SUBSURFACE_RADIUS, MAT_KEY_SUBSURFACE_SCALE,
       MAT_KEY_SUBSURFACE_ANISOTROPY, MAT_KEY_DIFFUSE_TRANSMISSION, MAT_KEY_DIFFUSE_TRANSMISSION_COLOR,
       MAT_KEY_N };
/* One row per key, read and checked by scene_parse_block: a declarative table, so
 * rows of keys of the same kind (colours, numbers in [0, 1]) are alike by design. */
static const KeySpec material_keys[MAT_KEY_N] = {
    [MAT_KEY_TYPE] = {"type", VK_WORD, 1, 0, 0, 0, 0,
                      "a material type (diffuse, metal, conductor, dielectric, principled, emissive, phong)"},
    [MAT_KEY_ALBEDO] = {"albedo", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_FUZZ] = {"fuzz", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_IOR] = {"ior", VK_NUMBER, 0, 0, INFINITY, 1, 1, "a number > 0"},
    [MAT_KEY_RADIANCE] = {"radiance", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_EMISSION] = {"emission", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SIDES] = {"sides", VK_UINT, 0, 1, 2, 0, 0, "1 or 2 (the sides that emit)"},
    [MAT_KEY_SPECULAR] = {"specular", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SHININESS] = {"shininess", VK_NUMBER, 0, 0, 1e6, 0, 0, "a number in [0, 1e6]"},
    [MAT_KEY_REFLECTIVE] = {"reflective", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_TRANSPARENT] = {"transparent", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_TEXTURE] = {"texture", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_ROUGHNESS] = {"roughness", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_ANISOTROPY] = {"anisotropy", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_ETA] = {"eta", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_K] = {"k", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_METAL] = {"metal", VK_WORD, 0, 0, 0, 0, 0, "a metal (Ag, Al, Au, Cr, Cu, Fe, Ni, Ti)"},
    [MAT_KEY_THIN] = {"thin", VK_WORD, 0, 0, 0, 0, 0, "on or off"},
    [MAT_KEY_METALLIC] = {"metallic", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_TRANSMISSION] = {"transmission", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_CLEARCOAT] = {"clearcoat", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_CLEARCOAT_ROUGHNESS] = {"clearcoat_roughness", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_STRENGTH] = {"strength", VK_NUMBER, 0, 0, 1e6, 0, 0, "a number in [0, 1e6]"},
    [MAT_KEY_METALLIC_ROUGHNESS] = {"metallic_roughness", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_NORMAL_MAP] = {"normal_map", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_NORMAL_SCALE] = {"normal_scale", VK_NUMBER, 0, 0, 100, 0, 0, "a number in [0, 100]"},
    [MAT_KEY_ALPHA] = {"alpha", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_ALPHA_MODE] = {"alpha_mode", VK_WORD, 0, 0, 0, 0, 0, "opaque, mask or blend"},
    [MAT_KEY_ALPHA_CUTOFF] = {"alpha_cutoff", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_EMISSION_TEXTURE] = {"emission_texture", VK_TEXTURE, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_ATTENUATION_COLOR] = {"attenuation_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_ATTENUATION_DISTANCE] = {"attenuation_distance", VK_NUMBER, 0, 0, INFINITY, 1, 0,
                                      "a number > 0"},
    [MAT_KEY_SPECULAR_FACTOR] = {"specular_factor", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_SPECULAR_COLOR] = {"specular_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SHEEN_COLOR] = {"sheen_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SHEEN_ROUGHNESS] = {"sheen_roughness", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_SUBSURFACE] = {"subsurface", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_SUBSURFACE_COLOR] = {"subsurface_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SUBSURFACE_RADIUS] = {"subsurface_radius", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [MAT_KEY_SUBSURFACE_SCALE] = {"subsurface_scale", VK_NUMBER, 0, 0, INFINITY, 1, 1, "a number > 0"},
    [MAT_KEY_SUBSURFACE_ANISOTROPY] = {"subsurface_anisotropy", VK_NUMBER, 0, -1, 1, 1, 1,
                                       "a number in (-1, 1)"},
    [MAT_KEY_DIFFUSE_TRANSMISSION] = {"diffuse_transmission", VK_NUMBER, 0, 0, 1, 0, 0, "a number in [0, 1]"},
    [MAT_KEY_DIFFUSE_TRANSMISSION_COLOR] = {"diffuse_transmission_color", VK_COLOR, 0, 0, 0, 0, 0, NULL},
};

/* Which keys each material type takes (bit i = material_keys[i]), and which it needs. */
static const struct {
    const char *name;
    uint type;
    unsigned long long allowed, required;   /* MAT_KEY_N > 32 */
} material_types[] = {
    {"diffuse", MAT_DIFFUSE,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_SIDES | 1ull << MAT_KEY_TEXTURE,
     1ull << MAT_KEY_ALBEDO},
    {"metal", MAT_METAL,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_FUZZ | 1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_SIDES |
     1ull << MAT_KEY_TEXTURE,
     1ull << MAT_KEY_ALBEDO},
    {"conductor", MAT_CONDUCTOR,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_TEXTURE | 1ull << MAT_KEY_ETA | 1ull << MAT_KEY_K | 1ull << MAT_KEY_METAL |
     1ull << MAT_KEY_SPECULAR | 1ull << MAT_KEY_ROUGHNESS | 1ull << MAT_KEY_ANISOTROPY | 1ull << MAT_KEY_EMISSION |
     1ull << MAT_KEY_SIDES,
     0},
    {"dielectric", MAT_DIELECTRIC,
     1ull << MAT_KEY_IOR | 1ull << MAT_KEY_ROUGHNESS | 1ull << MAT_KEY_ANISOTROPY | 1ull << MAT_KEY_THIN |
     1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_SIDES, 0},
    {"principled", MAT_PRINCIPLED,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_TEXTURE | 1ull << MAT_KEY_METALLIC | 1ull << MAT_KEY_ROUGHNESS |
     1ull << MAT_KEY_ANISOTROPY | 1ull << MAT_KEY_TRANSMISSION | 1ull << MAT_KEY_IOR | 1ull << MAT_KEY_THIN |
     1ull << MAT_KEY_CLEARCOAT | 1ull << MAT_KEY_CLEARCOAT_ROUGHNESS | 1ull << MAT_KEY_EMISSION | 1ull << MAT_KEY_STRENGTH |
     1ull << MAT_KEY_METALLIC_ROUGHNESS | 1ull << MAT_KEY_NORMAL_MAP | 1ull << MAT_KEY_NORMAL_SCALE | 1ull << MAT_KEY_SIDES |
     1ull << MAT_KEY_ALPHA | 1ull << MAT_KEY_ALPHA_MODE | 1ull << MAT_KEY_ALPHA_CUTOFF | 1ull << MAT_KEY_EMISSION_TEXTURE |
     1ull << MAT_KEY_ATTENUATION_COLOR | 1ull << MAT_KEY_ATTENUATION_DISTANCE | 1ull << MAT_KEY_SPECULAR_FACTOR |
     1ull << MAT_KEY_SPECULAR_COLOR | 1ull << MAT_KEY_SHEEN_COLOR | 1ull << MAT_KEY_SHEEN_ROUGHNESS |
     1ull << MAT_KEY_SUBSURFACE | 1ull << MAT_KEY_SUBSURFACE_COLOR | 1ull << MAT_KEY_SUBSURFACE_RADIUS |
     1ull << MAT_KEY_SUBSURFACE_SCALE | 1ull << MAT_KEY_SUBSURFACE_ANISOTROPY | 1ull << MAT_KEY_DIFFUSE_TRANSMISSION |
     1ull << MAT_KEY_DIFFUSE_TRANSMISSION_COLOR,
     0},
    {"emissive", MAT_EMISSIVE, 1ull << MAT_KEY_RADIANCE | 1ull << MAT_KEY_SIDES, 1ull << MAT_KEY_RADIANCE},
    {"phong", MAT_PHONG,
     1ull << MAT_KEY_ALBEDO | 1ull << MAT_KEY_SPECULAR | 1ull << MAT_KEY_SHININESS | 1ull << MAT_KEY_REFLECTIVE |
     1ull << MAT_KEY_TRANSPARENT | 1ull << MAT_KEY_IOR | 1ull << MAT_KEY_TEXTURE | 1ull << MAT_KEY_EMISSION |
     1ull << MAT_KEY_SIDES,
     1ull << MAT_KEY_ALBEDO},
};
#define N_MATERIAL_TYPES (sizeof material_types / sizeof material_types[0])

/* A conductor's Fresnel term: exactly one of a preset (`metal`), a complex index (`eta`
 * with `k`) or an artist's reflectance at normal incidence (`specular`). */
static Status parse_conductor(Parser *p, Lexer *lx, const Token *kw, const Value *v, Material *m)
{
    int n = v[MAT_KEY_METAL].given + (v[MAT_KEY_ETA].given || v[MAT_KEY_K].given) + v[MAT_KEY_SPECULAR].given;
    if (n != 1)
        return lex_error_at(lx, kw, p->err,
                            "a conductor needs exactly one of 'metal', 'eta' and 'k', or 'specular'");
    if (v[MAT_KEY_ETA].given != v[MAT_KEY_K].given)
        return lex_error_at(lx, v[MAT_KEY_ETA].given ? &v[MAT_KEY_ETA].key : &v[MAT_KEY_K].key, p->err,
                            "a conductor's 'eta' needs its 'k' (the complex index eta + i k)");
    if (v[MAT_KEY_SPECULAR].given) {
        *m = material_conductor_f0(v[MAT_KEY_SPECULAR].v, 0.0f);
    } else if (v[MAT_KEY_METAL].given) {
        const Token *w = &v[MAT_KEY_METAL].word;
        vec3 eta, k;
        if (!material_metal_preset(w->text, w->len, &eta, &k))
            return lex_expected(lx, w, material_keys[MAT_KEY_METAL].what, p->err);
        *m = material_conductor(eta, k, 0.0f);
    } else {
        *m = material_conductor(v[MAT_KEY_ETA].v, v[MAT_KEY_K].v, 0.0f);
    }
    if (v[MAT_KEY_ALBEDO].given) m->albedo = v[MAT_KEY_ALBEDO].v;
    return ST_OK;
}

/* glTF's alpha: `alpha` (baseColorFactor's A, times the base-colour texture's alpha),
 * `alpha_mode` opaque (default; alpha ignored), mask (cut out below `alpha_cutoff`,
 * default 0.5) or blend (stochastic opacity). A cutoff means nothing outside mask, so it
 * is refused there rather than silently ignored. */
static Status parse_alpha(Parser *p, Lexer *lx, const Value *v, Material *m)
{
    if (v[MAT_KEY_ALPHA].given) m->alpha = v[MAT_KEY_ALPHA].f;
    uint mode = 0u;
    if (v[MAT_KEY_ALPHA_MODE].given) {
        const Token *w = &v[MAT_KEY_ALPHA_MODE].word;
        if (tok_is(w, "mask")) mode = MAT_ALPHA_MASK;
        else if (tok_is(w, "blend")) mode = MAT_ALPHA_BLEND;
        else if (!tok_is(w, "opaque")) return lex_expected(lx, w, material_keys[MAT_KEY_ALPHA_MODE].what, p->err);
    }
    if (v[MAT_KEY_ALPHA_CUTOFF].given && mode != MAT_ALPHA_MASK)
        return lex_error_at(lx, &v[MAT_KEY_ALPHA_CUTOFF].key, p->err,
                            "'alpha_cutoff' needs 'alpha_mode mask'");
    if (v[MAT_KEY_ALPHA_CUTOFF].given) m->alpha_cutoff = v[MAT_KEY_ALPHA_CUTOFF].f;
    m->flags |= mode;
    return ST_OK;
}

/* The principled keys of the glTF extensions: KHR_materials_volume's attenuation (read
 * in a solid, `thin off`), KHR_materials_specular's factor and colour,
 * KHR_materials_sheen's colour and roughness, and KHR_materials_diffuse_transmission's
 * share and colour (a colour above 1 would pass on more light than arrives). */
static Status parse_principled_layers(Parser *p, Lexer *lx, const Value *v, Material *m)
{
    vec3 color = v[MAT_KEY_ATTENUATION_COLOR].given ? v[MAT_KEY_ATTENUATION_COLOR].v : v3s(1.0f);
    float distance = v[MAT_KEY_ATTENUATION_DISTANCE].given ? v[MAT_KEY_ATTENUATION_DISTANCE].f : INFINITY;
    m->absorption = material_absorption(color, distance);
    if (v[MAT_KEY_SPECULAR_FACTOR].given) m->specular_factor = v[MAT_KEY_SPECULAR_FACTOR].f;
    if (v[MAT_KEY_SPECULAR_COLOR].given) m->specular_color = v[MAT_KEY_SPECULAR_COLOR].v;
    if (v[MAT_KEY_SHEEN_COLOR].given) m->sheen_color = v[MAT_KEY_SHEEN_COLOR].v;
    if (v[MAT_KEY_SHEEN_ROUGHNESS].given) m->sheen_roughness = v[MAT_KEY_SHEEN_ROUGHNESS].f;
    if (v[MAT_KEY_DIFFUSE_TRANSMISSION].given) m->diffuse_transmission = v[MAT_KEY_DIFFUSE_TRANSMISSION].f;
    if (v[MAT_KEY_DIFFUSE_TRANSMISSION_COLOR].given) {
        vec3 c = v[MAT_KEY_DIFFUSE_TRANSMISSION_COLOR].v;
        if (!(c.x <= 1.0f && c.y <= 1.0f && c.z <= 1.0f))
            return lex_error_at(lx, &v[MAT_KEY_DIFFUSE_TRANSMISSION_COLOR].value, p->err,
                                "'diffuse_transmission_color' must be in [0, 1]");
        m->diffuse_transmission_color = c;
    }
    return ST_OK;
}

/* Subsurface scattering (scene/subsurface.h, docs/subsurface.md): `subsurface` W > 0
 * gives the material an interior medium from `subsurface_color` (default: the albedo)
 * and `subsurface_radius` (the mean free path per channel, default 1 1 1) times
 * `subsurface_scale` (default 1), with `subsurface_anisotropy` g (default 0). Only a
 * solid has an inside, and its absorption would be charged twice, so `thin on` and the
 * attenuation keys are refused with it. W = 0 (the default) makes no medium: the
 * material is what it was before subsurface scattering, to the bit. */
static Status parse_subsurface(Parser *p, Lexer *lx, const Value *v, const char *name, Material *m)
{
    if (!v[MAT_KEY_SUBSURFACE].given || !(v[MAT_KEY_SUBSURFACE].f > 0.0f)) return ST_OK;
    const Token *key = &v[MAT_KEY_SUBSURFACE].key;
    if (m->flags & MAT_THIN)
        return lex_error_at(lx, key, p->err, "'subsurface' needs a solid: it cannot be combined with 'thin on'");
    if (v[MAT_KEY_ATTENUATION_COLOR].given || v[MAT_KEY_ATTENUATION_DISTANCE].given)
        return lex_error_at(lx, key, p->err, "'subsurface' cannot be combined with 'attenuation_color' or "
                            "'attenuation_distance' (the subsurface medium absorbs by its colour)");
    vec3 color = v[MAT_KEY_SUBSURFACE_COLOR].given ? v[MAT_KEY_SUBSURFACE_COLOR].v : m->albedo;
    if (!(color.x <= 1.0f && color.y <= 1.0f && color.z <= 1.0f))
        return lex_error_at(lx, v[MAT_KEY_SUBSURFACE_COLOR].given ? &v[MAT_KEY_SUBSURFACE_COLOR].value : key, p->err,
                            "'subsurface_color' must be in [0, 1] (the share of light the interior gives back)%s",
                            v[MAT_KEY_SUBSURFACE_COLOR].given ? "" : "; it defaults to 'albedo'");
    vec3 radius = v[MAT_KEY_SUBSURFACE_RADIUS].given ? v[MAT_KEY_SUBSURFACE_RADIUS].v : v3s(1.0f);
    if (!(radius.x > 0.0f && radius.y > 0.0f && radius.z > 0.0f))
        return lex_error_at(lx, &v[MAT_KEY_SUBSURFACE_RADIUS].value, p->err,
                            "'subsurface_radius' must be > 0 in every channel (a mean free path)");
    float scale = v[MAT_KEY_SUBSURFACE_SCALE].given ? v[MAT_KEY_SUBSURFACE_SCALE].f : 1.0f;
    vec3 mfp = v3_scale(radius, scale), sa, ss;
    subsurface_coefficients(color, mfp, &sa, &ss);
    vec3 t = v3_add(sa, ss);
    if (!(mfp.x > 0.0f && mfp.y > 0.0f && mfp.z > 0.0f) || !isfinite(t.x) || !isfinite(t.y) || !isfinite(t.z))
        return lex_error_at(lx, v[MAT_KEY_SUBSURFACE_SCALE].given ? &v[MAT_KEY_SUBSURFACE_SCALE].key
                                                                  : &v[MAT_KEY_SUBSURFACE_RADIUS].key, p->err,
                            "the subsurface extinction 1 / (subsurface_radius x subsurface_scale) is beyond the "
                            "largest float (about 3.4e38)");
    float g = v[MAT_KEY_SUBSURFACE_ANISOTROPY].given ? v[MAT_KEY_SUBSURFACE_ANISOTROPY].f : 0.0f;
    return scene_add_subsurface(p->s, m, name ? name : "", v[MAT_KEY_SUBSURFACE].f, sa, ss, g, p->err);
}

/* Reads a material's `{ ... }`; a NULL name makes an anonymous (inline) material. */
Status scene_parse_material_block(Parser *p, Lexer *lx, const Token *kw, int brace_taken,
                                  const char *name, uint *index)
{
    Value v[MAT_KEY_N];
    Status st = scene_parse_block(p, lx, kw, brace_taken, "material", material_keys, MAT_KEY_N, v);
    if (st) return st;
    size_t ti;
    for (ti = 0; ti < N_MATERIAL_TYPES; ti++)
        if (tok_is(&v[MAT_KEY_TYPE].word, material_types[ti].name)) break;
    if (ti == N_MATERIAL_TYPES)
        return lex_expected(lx, &v[MAT_KEY_TYPE].word, material_keys[MAT_KEY_TYPE].what, p->err);
    unsigned long long allowed = material_types[ti].allowed | 1ull << MAT_KEY_TYPE;
    for (int i = 0; i < MAT_KEY_N; i++) {
        if (!v[i].given || (allowed & (1ull << i))) continue;
        char what[1024];   /* the principled list alone is over 500 characters */
        size_t o = (size_t)snprintf(what, sizeof what, "a %s material key (type",
                                    material_types[ti].name);
        for (int j = 1; j < MAT_KEY_N; j++)
            if (allowed & (1ull << j))
                o += (size_t)snprintf(what + o, sizeof what - o, ", %s", material_keys[j].key);
        snprintf(what + o, sizeof what - o, ") or '}'");
        return lex_expected(lx, &v[i].key, what, p->err);
    }
    for (int i = 0; i < MAT_KEY_N; i++)
        if ((material_types[ti].required & (1ull << i)) && !v[i].given)
            return lex_error_at(lx, kw, p->err, "a material of type %s needs '%s'",
                                material_types[ti].name, material_keys[i].key);
    Material m;
    switch (material_types[ti].type) {
    case MAT_CONDUCTOR:
        if ((st = parse_conductor(p, lx, kw, v, &m))) return st;
        break;
    case MAT_METAL:
        m = material_metal(v[MAT_KEY_ALBEDO].v, v[MAT_KEY_FUZZ].given ? v[MAT_KEY_FUZZ].f : 0.0f);
        break;
    case MAT_DIELECTRIC:
        m = material_dielectric(v[MAT_KEY_IOR].given ? v[MAT_KEY_IOR].f : 1.5f);
        break;
    case MAT_PRINCIPLED:
        m = material_principled(v[MAT_KEY_ALBEDO].given ? v[MAT_KEY_ALBEDO].v : v3s(1.0f),
                                v[MAT_KEY_METALLIC].given ? v[MAT_KEY_METALLIC].f : 1.0f,
                                v[MAT_KEY_ROUGHNESS].given ? v[MAT_KEY_ROUGHNESS].f : 1.0f);
        if (v[MAT_KEY_TRANSMISSION].given) m.transmission = v[MAT_KEY_TRANSMISSION].f;
        if (v[MAT_KEY_IOR].given) m.ior = v[MAT_KEY_IOR].f;
        if (v[MAT_KEY_CLEARCOAT].given) m.clearcoat = v[MAT_KEY_CLEARCOAT].f;
        if (v[MAT_KEY_CLEARCOAT_ROUGHNESS].given) m.clearcoat_roughness = v[MAT_KEY_CLEARCOAT_ROUGHNESS].f;
        if (v[MAT_KEY_METALLIC_ROUGHNESS].given) m.texture_rm = (uint)v[MAT_KEY_METALLIC_ROUGHNESS].u;
        if (v[MAT_KEY_NORMAL_MAP].given) m.texture_normal = (uint)v[MAT_KEY_NORMAL_MAP].u;
        if (v[MAT_KEY_NORMAL_SCALE].given) m.normal_scale = v[MAT_KEY_NORMAL_SCALE].f;
        if (v[MAT_KEY_EMISSION_TEXTURE].given) m.texture_emission = (uint)v[MAT_KEY_EMISSION_TEXTURE].u;
        if ((st = parse_alpha(p, lx, v, &m))) return st;
        if ((st = parse_principled_layers(p, lx, v, &m))) return st;
        break;
    case MAT_EMISSIVE:
        m = material_emissive(v[MAT_KEY_RADIANCE].v);
        break;
    case MAT_PHONG:
        m = material_phong(v[MAT_KEY_ALBEDO].v, v[MAT_KEY_SPECULAR].given ? v[MAT_KEY_SPECULAR].v : v3s(0.0f),
                           v[MAT_KEY_SHININESS].given ? v[MAT_KEY_SHININESS].f : 0.0f);
        if (v[MAT_KEY_REFLECTIVE].given) m.reflective = v[MAT_KEY_REFLECTIVE].v;
        if (v[MAT_KEY_TRANSPARENT].given) m.transparent = v[MAT_KEY_TRANSPARENT].v;
        m.ior = v[MAT_KEY_IOR].given ? v[MAT_KEY_IOR].f : 1.5f;
        break;
    default:
        m = material_diffuse(v[MAT_KEY_ALBEDO].v);
        break;
    }
    if (v[MAT_KEY_THIN].given) {
        const Token *w = &v[MAT_KEY_THIN].word;
        if (!tok_is(w, "on") && !tok_is(w, "off"))
            return lex_expected(lx, w, material_keys[MAT_KEY_THIN].what, p->err);
        if (tok_is(w, "on")) m.flags |= MAT_THIN;
    }
    /* a surface that both reflects and glows (the furnace test's sphere); glTF's
     * emissive factor times KHR_materials_emissive_strength */
    if (v[MAT_KEY_EMISSION].given) m.emission = v[MAT_KEY_EMISSION].v;
    if (v[MAT_KEY_STRENGTH].given) m.emission = v3_scale(m.emission, v[MAT_KEY_STRENGTH].f);
    if (v[MAT_KEY_SIDES].given && v[MAT_KEY_SIDES].u == 2) m.flags |= MAT_TWO_SIDED;
    if (v[MAT_KEY_TEXTURE].given) m.texture = (uint)v[MAT_KEY_TEXTURE].u;
    if (v[MAT_KEY_ROUGHNESS].given) m.roughness = v[MAT_KEY_ROUGHNESS].f;
    if (v[MAT_KEY_ANISOTROPY].given) m.anisotropy = v[MAT_KEY_ANISOTROPY].f;
    if ((st = parse_subsurface(p, lx, v, name, &m))) return st;
    /* inline materials get the empty name, which no named material can have, so a
     * lookup never finds them */
    if ((st = scene_add_material(p->s, name ? name : "", m, index, p->err))) return st;
    if (array_reserve((void **)&p->material_at, &p->cap_material_at, p->s->n_materials,
                      sizeof(char *)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    while (p->n_material_at < p->s->n_materials) p->material_at[p->n_material_at++] = NULL;
    /* only for messages: a failed copy just loses the "defined at" part */
    if (name) p->material_at[*index] = reader_where(lx, kw);
    return ST_OK;
}

Status scene_parse_material(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
        return lex_expected(lx, &t, "a material name", p->err);
    char *name = tok_copy(&t);
    if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
    uint prev = scene_find_material(p->s, name);
    if (prev != NO_INDEX) {
        char shown[64];
        tok_describe(&t, shown, sizeof shown);
        const char *where = prev < p->n_material_at ? p->material_at[prev] : NULL;
        st = lex_error_at(lx, &t, p->err, "material '%s' is already defined%s%s%s", shown,
                          where ? " (at " : "", where ? where : "", where ? ")" : "");
        free(name);
        return st;
    }
    uint index;
    st = scene_parse_material_block(p, lx, kw, 0, name, &index);
    free(name);
    return st;
}

enum { TX_TYPE, TX_FILE, TX_ENCODING, TX_WRAP, TX_COLOR0, TX_COLOR1, TX_SPACE, TX_SCALE, TX_N };
static const KeySpec texture_keys[TX_N] = {
    [TX_TYPE] = {"type", VK_WORD, 1, 0, 0, 0, 0, "a texture type (image, checker)"},
    [TX_FILE] = {"file", VK_PATH, 0, 0, 0, 0, 0, NULL},
    [TX_ENCODING] = {"encoding", VK_WORD, 0, 0, 0, 0, 0, "srgb or linear"},
    [TX_WRAP] = {"wrap", VK_WORD, 0, 0, 0, 0, 0, "repeat or clamp"},
    [TX_COLOR0] = {"color0", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [TX_COLOR1] = {"color1", VK_COLOR, 0, 0, 0, 0, 0, NULL},
    [TX_SPACE] = {"space", VK_WORD, 0, 0, 0, 0, 0, "uv or solid"},
    /* TEXTURE_MAX_MAP_ENTRY: a larger scale leaves no fraction to pick a texel by */
    [TX_SCALE] = {"scale", VK_NUMBER, 0, 0, TEXTURE_MAX_MAP_ENTRY, 1, 0, "a number in (0, 16777216]"},
};

Status scene_parse_texture(Parser *p, Lexer *lx, const Token *kw)
{
    Token t;
    Status st = lex_next(lx, &t, p->err);
    if (st) return st;
    if ((t.kind != TOK_WORD && t.kind != TOK_STRING) || t.len == 0)
        return lex_expected(lx, &t, "a texture name", p->err);
    char *name = tok_copy(&t);
    if (!name) return error_set(p->err, ST_INTERNAL, "out of memory");
    if (scene_find_texture(p->s, name) != NO_INDEX) {
        char shown[64];
        tok_describe(&t, shown, sizeof shown);
        free(name);
        return lex_error_at(lx, &t, p->err, "texture '%s' is already defined", shown);
    }
    Value v[TX_N];
    if ((st = scene_parse_block(p, lx, kw, 0, "texture", texture_keys, TX_N, v))) {
        free(name);
        return st;
    }
    int image = tok_is(&v[TX_TYPE].word, "image");
    unsigned allowed = 1u << TX_TYPE | 1u << TX_SCALE;
    if (image) allowed |= 1u << TX_FILE | 1u << TX_ENCODING | 1u << TX_WRAP;
    else if (tok_is(&v[TX_TYPE].word, "checker")) allowed |= 1u << TX_COLOR0 | 1u << TX_COLOR1 | 1u << TX_SPACE;
    else st = lex_expected(lx, &v[TX_TYPE].word, texture_keys[TX_TYPE].what, p->err);
    for (int i = 0; !st && i < TX_N; i++)
        if (v[i].given && !(allowed & (1u << i)))
            st = lex_error_at(lx, &v[i].key, p->err, "an %s texture has no '%s'", image ? "image" : "checker",
                              texture_keys[i].key);
    struct { int index; const char *a, *b; } words[] = {
        {TX_ENCODING, "srgb", "linear"}, {TX_WRAP, "repeat", "clamp"}, {TX_SPACE, "uv", "solid"} };
    int second[TX_N] = {0};
    for (size_t i = 0; !st && i < sizeof words / sizeof words[0]; i++) {
        const Value *w = &v[words[i].index];
        if (!w->given) continue;
        if (tok_is(&w->word, words[i].b)) second[words[i].index] = 1;
        else if (!tok_is(&w->word, words[i].a))
            st = lex_expected(lx, &w->word, texture_keys[words[i].index].what, p->err);
    }
    if (!st && image && !v[TX_FILE].given)
        st = lex_error_at(lx, kw, p->err, "an image texture needs 'file'");
    float scale = v[TX_SCALE].given ? v[TX_SCALE].f : 1.0f;
    if (!st && image) {
        const Token *f = &v[TX_FILE].word;
        char *path = scene_path_beside(lx->path, f->text, f->len);
        if (!path) st = error_set(p->err, ST_INTERNAL, "out of memory");
        uint index;
        if (!st) st = texture_load_image(p->s, name, path, second[TX_ENCODING], second[TX_WRAP], &index, p->err);
        free(path);
        if (st == ST_IO || st == ST_INPUT) reader_annotate(lx, f, p->err);
        if (!st) texture_set_scale_offset(&p->s->textures[index], scale, scale, 0.0f, 0.0f);
    } else if (!st) {
        Texture tx = texture_make_checker(v[TX_COLOR0].given ? v[TX_COLOR0].v : v3s(0.8f),
                                     v[TX_COLOR1].given ? v[TX_COLOR1].v : v3s(0.2f), scale, second[TX_SPACE]);
        st = scene_add_texture(p->s, name, NULL, tx, NULL, p->err);
    }
    free(name);
    return st;
}
