/* pbrt_material.c — pbrt-v4 materials and textures (pbrt_reader.h, docs/pbrt.md). */
#include "io/pbrt_reader.h"
#include "scene/media.h"
#include "scene/subsurface.h"

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


/* ------------------------------------------------------------------ materials */

/* pbrt's roughness to clpt's perceptual roughness (GGX alpha = roughness^2); pbrt
 * remaps its roughness to alpha = sqrt(r) unless remaproughness is false. */
static float clpt_roughness(double r, int remap)
{
    double alpha = remap ? sqrt(fmax(r, 0)) : fmax(r, 0);
    return (float)fmin(sqrt(alpha), 1.0);
}

/* prefix + roughness, or + uroughness/vroughness, as clpt's roughness and anisotropy */
static Status get_roughness_named(Parser *p, const Lexer *lx, const char *prefix, double dflt, float *rough,
                                  float *aniso)
{
    double r = dflt, u = -1, v = -1;
    int remap = 1;
    char nr[48], nu[48], nv[48];
    snprintf(nr, sizeof nr, "%sroughness", prefix);
    snprintf(nu, sizeof nu, "%suroughness", prefix);
    snprintf(nv, sizeof nv, "%svroughness", prefix);
    Status st;
    if ((st = pbrt_get_float_tex(p, lx, nr, &r)) || (st = pbrt_get_float_tex(p, lx, nu, &u)) ||
        (st = pbrt_get_float_tex(p, lx, nv, &v)) || (st = pbrt_get_bool(p, lx, "remaproughness", &remap)))
        return st;
    if (u < 0) u = r;
    if (v < 0) v = r;
    double au = pow(clpt_roughness(u, remap), 2), av = pow(clpt_roughness(v, remap), 2);
    double hi = fmax(au, av), lo = fmin(au, av);
    *rough = (float)sqrt(sqrt(au * av));
    /* alpha_x / alpha_y = 1 / (1 - 0.9 A) (docs/scene-format.md); the direction of the
     * stretch is clpt's, not the file's */
    *aniso = hi > 0 ? (float)fmin((1 - lo / hi) / 0.9, 1.0) : 0.0f;
    return ST_OK;
}

static Status get_roughness(Parser *p, const Lexer *lx, Material *m, double dflt)
{
    return get_roughness_named(p, lx, "", dflt, &m->roughness, &m->anisotropy);
}

static Status conductor_params(Parser *p, const Lexer *lx, const char *eta_name, const char *k_name,
                               const char *refl_name, Material *m)
{
    vec3 eta, k, refl = v3(0, 0, 0);
    material_metal_preset("Cu", 2, &eta, &k);   /* pbrt's default conductor is copper */
    int has_refl = 0;
    Status st;
    if ((st = pbrt_get_spectrum(p, lx, eta_name, &eta, NULL, NULL)) || (st = pbrt_get_spectrum(p, lx, k_name, &k, NULL, NULL)) ||
        (st = pbrt_get_spectrum(p, lx, refl_name, &refl, NULL, &has_refl)))
        return st;
    float rough = m->roughness, aniso = m->anisotropy;
    *m = has_refl ? material_conductor_f0(refl, rough) : material_conductor(eta, k, rough);
    m->roughness = rough;
    m->anisotropy = aniso;
    return ST_OK;
}

static Status texture_of(Parser *p, const Lexer *lx, const char *name, vec3 *albedo, uint *texture)
{
    const PTexture *tex;
    Status st = pbrt_get_spectrum(p, lx, name, albedo, &tex, NULL);
    if (st) return st;
    if (tex) *texture = tex->index;
    return ST_OK;
}

static PPending *pending_of(Parser *p, uint index)
{
    for (size_t i = 0; i < p->n_pending; i++)
        if (p->pending[i].index == index && !p->pending[i].defined) return &p->pending[i];
    return NULL;
}

/* pbrt's mix: its two named materials (defined before it, so a mix never contains
 * itself) and `amount`, a float or a float texture (an image's red channel), chosen per
 * hit by the kernels (kernels/material/mix.h). */
static Status make_mix(Parser *p, const Lexer *lx, const Token *type, Material *m)
{
    Param *pa = pbrt_param_find(p, "materials");
    if (!pa || pa->type != PT_STRING || pa->n != 2)
        return lex_error_at(lx, type, p->err, "a mix material needs \"string materials\" with two names");
    uint32_t parts[2];
    for (int i = 0; i < 2; i++) {
        const Token *named = &p->pl.strs[pa->first + i];
        if (!strmap_find(&p->named_material, named->text, named->len, &parts[i]) || pending_of(p, parts[i]))
            return lex_error_at(lx, named, p->err, "material '%.*s' is not defined (MakeNamedMaterial defines it)",
                                (int)(named->len > 40 ? 40 : named->len), named->text);
    }
    double amount = 0.5;
    uint amount_tex = NO_INDEX;
    Param *am = pbrt_param_find(p, "amount");
    Status st;
    if (am && am->type == PT_TEXTURE) {
        const PTexture *tex;
        vec3 c = v3(0.5f, 0.5f, 0.5f);
        if ((st = pbrt_get_spectrum(p, lx, "amount", &c, &tex, NULL))) return st;
        amount = tex ? 1.0 : c.x;
        if (tex) amount_tex = tex->index;
    } else if ((st = pbrt_get_float(p, lx, "amount", &amount))) {
        return st;
    }
    /* the kernels follow MIX_MAX_DEPTH mixes from a hit's material */
    uint da = scene_mix_depth(p->s, parts[0]), db = scene_mix_depth(p->s, parts[1]);
    if ((da > db ? da : db) >= MIX_MAX_DEPTH)
        return lex_error_at(lx, type, p->err, "mix materials nest more than %u deep", MIX_MAX_DEPTH);
    *m = material_mix(parts[0], parts[1], (float)amount, amount_tex);
    return ST_OK;
}

/* The medium between a coat and its base: thickness, albedo, g, maxdepth, nsamples
 * (pbrt-v4's defaults are material_coated_*'s). */
static Status coated_medium(Parser *p, const Lexer *lx, Material *m)
{
    double thickness = m->layer_thickness, g = m->layer_g;
    long depth = (long)m->layer_depth, samples = (long)m->layer_samples;
    Status st;
    if ((st = pbrt_get_float_tex(p, lx, "thickness", &thickness)) || (st = pbrt_get_float_tex(p, lx, "g", &g)) ||
        (st = pbrt_get_spectrum(p, lx, "albedo", &m->layer_albedo, NULL, NULL)) ||
        (st = pbrt_get_int(p, lx, "maxdepth", &depth)) || (st = pbrt_get_int(p, lx, "nsamples", &samples)))
        return st;
    if (!(thickness >= 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "thickness"), ">= 0");
    if (!(g > -1 && g < 1)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "g"), "between -1 and 1");
    if (depth < 0 || depth > 256) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "maxdepth"), "0 to 256");
    if (samples < 1 || samples > 64) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "nsamples"), "1 to 64");
    m->layer_thickness = (float)thickness;
    m->layer_g = (float)g;
    m->layer_depth = (uint)depth;
    m->layer_samples = (uint)samples;
    return ST_OK;
}

/* pbrt-v4's coateddiffuse and coatedconductor: MAT_LAYERED (kernels/bsdf/layered.h). A
 * conductor's `reflectance` becomes pbrt's index for it, eta 1 and k = 2 sqrt(r) /
 * sqrt(1 - r), as CoatedConductorMaterial does. */
static Status make_coated(Parser *p, const Lexer *lx, int conductor, Material *m)
{
    Status st;
    double eta = 1.5;
    if (conductor) {
        Material base = material_conductor(v3(1, 1, 1), v3(0, 0, 0), 0);
        if ((st = conductor_params(p, lx, "conductor.eta", "conductor.k", "reflectance", &base))) return st;
        vec3 e = base.eta, k = base.k;
        if (base.flags & MAT_F0) {
            float r[3] = {base.specular.x, base.specular.y, base.specular.z}, kk[3];
            for (int i = 0; i < 3; i++) {
                float c = r[i] < 0.9999f ? r[i] : 0.9999f;
                kk[i] = 2.0f * sqrtf(c) / sqrtf(1.0f - c);
            }
            e = v3(1, 1, 1);
            k = v3(kk[0], kk[1], kk[2]);
        }
        *m = material_coated_conductor(e, k, 0, 0);
        if ((st = get_roughness_named(p, lx, "conductor.", 0, &m->base_roughness, &m->base_anisotropy)) ||
            (st = get_roughness_named(p, lx, "interface.", 0, &m->roughness, &m->anisotropy)) ||
            (st = pbrt_get_float_tex(p, lx, "interface.eta", &eta)))
            return st;
    } else {
        *m = material_coated_diffuse(v3(0.5f, 0.5f, 0.5f), 0);
        if ((st = texture_of(p, lx, "reflectance", &m->albedo, &m->texture)) || (st = get_roughness(p, lx, m, 0)) ||
            (st = pbrt_get_float_tex(p, lx, "eta", &eta)))
            return st;
    }
    /* pbrt-v4 takes an index of 0 as 1 (no interface) */
    if (eta < 0) return pbrt_param_type_error(p, lx, pbrt_param_find(p, conductor ? "interface.eta" : "eta"), ">= 0");
    m->ior = eta == 0 ? 1.0f : (float)eta;
    return coated_medium(p, lx, m);
}

/* pbrt-v4's subsurface material as clpt's principled material with subsurface 1
 * (docs/subsurface.md, docs/pbrt.md): its interior from `reflectance` and `mfp`
 * (default 1) by clpt's albedo inversion (pbrt-v4 inverts its photon-beam-diffusion
 * table instead: SubsurfaceFromDiffuse), or from `sigma_a` and `sigma_s` as they are
 * (default pbrt-v4's RGB .0011 .0024 .014 and 2.55 3.21 3.77), each times `scale`;
 * `g`, `eta` (default 1.33) and the roughness keys. A measured medium by `name` is a
 * warning, and the defaults stand in. The entry is the principled dielectric
 * (Schlick's Fresnel, pbrt-v4 the exact one), the exit Lambertian (pbrt-v4's
 * NormalizedFresnelBxDF weighs it by the Fresnel transmission). */
static Status make_subsurface(Parser *p, const Lexer *lx, const Token *type, Material *m)
{
    Status st;
    double eta = 1.33, g = 0.0, scale = 1.0;
    vec3 sa = v3(0.0011f, 0.0024f, 0.014f), ss = v3(2.55f, 3.21f, 3.77f), refl = v3s(0.0f), mfp = v3s(1.0f);
    int has_sa = 0, has_ss = 0, has_refl = 0;
    const Token *name = NULL;
    *m = material_principled(v3s(1.0f), 0.0f, 0.0f);
    if ((st = pbrt_get_float(p, lx, "eta", &eta)) || (st = pbrt_get_float(p, lx, "g", &g)) ||
        (st = pbrt_get_float(p, lx, "scale", &scale)) || (st = pbrt_get_string(p, lx, "name", &name)) ||
        (st = pbrt_get_spectrum(p, lx, "sigma_a", &sa, NULL, &has_sa)) ||
        (st = pbrt_get_spectrum(p, lx, "sigma_s", &ss, NULL, &has_ss)) ||
        (st = pbrt_get_spectrum(p, lx, "reflectance", &refl, NULL, &has_refl)) ||
        (st = pbrt_get_spectrum(p, lx, "mfp", &mfp, NULL, NULL)) || (st = get_roughness(p, lx, m, 0)))
        return st;
    if (!(eta > 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "eta"), "> 0");
    if (!(g > -1 && g < 1)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "g"), "between -1 and 1");
    if (!(scale > 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "scale"), "> 0");
    if (has_sa != has_ss)
        return lex_error_at(lx, type, p->err, "the subsurface material's \"%s\" needs its \"%s\"",
                            has_sa ? "sigma_a" : "sigma_s", has_sa ? "sigma_s" : "sigma_a");
    if (name) {
        char key[96];
        snprintf(key, sizeof key, "subsurface name %.*s", (int)(name->len > 40 ? 40 : name->len), name->text);
        if ((st = warn_once(p, lx, name, key, "the measured medium \"%.*s\" is not supported; pbrt-v4's default "
                            "sigma_a and sigma_s are used", (int)(name->len > 40 ? 40 : name->len), name->text)))
            return st;
    }
    if (!(sa.x >= 0 && sa.y >= 0 && sa.z >= 0))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "sigma_a"), "values >= 0");
    if (!(ss.x >= 0 && ss.y >= 0 && ss.z >= 0))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "sigma_s"), "values >= 0");
    if (!(mfp.x > 0 && mfp.y > 0 && mfp.z > 0))
        return pbrt_param_type_error(p, lx, pbrt_param_find(p, "mfp"), "values > 0");
    if (has_refl && !has_sa && !name) {
        vec3 color = v3(fminf(refl.x, 1.0f), fminf(refl.y, 1.0f), fminf(refl.z, 1.0f));
        subsurface_coefficients(color, v3_scale(mfp, (float)scale), &sa, &ss);
    } else {
        sa = v3_scale(sa, (float)scale);
        ss = v3_scale(ss, (float)scale);
    }
    vec3 t = v3_add(sa, ss);
    if (!isfinite(t.x) || !isfinite(t.y) || !isfinite(t.z))
        return lex_error_at(lx, type, p->err, "the subsurface material's extinction (sigma_a + sigma_s, times "
                            "scale) is beyond the largest float (about 3.4e38)");
    m->ior = (float)eta;
    return scene_add_subsurface(p->s, m, "pbrt subsurface", 1.0f, sa, ss, (float)g, p->err);
}

/* Builds the material of type `type` from the current parameter list. */
static Status make_material(Parser *p, const Lexer *lx, const Token *type, Material *m, const char *what)
{
    Status st;
    if (pbrt_tok_eq(type, "diffuse")) {
        *m = material_diffuse(v3(0.5f, 0.5f, 0.5f));
        st = texture_of(p, lx, "reflectance", &m->albedo, &m->texture);
    } else if (pbrt_tok_eq(type, "conductor")) {
        *m = material_conductor(v3(1, 1, 1), v3(0, 0, 0), 0);
        if ((st = get_roughness(p, lx, m, 0))) return st;
        st = conductor_params(p, lx, "eta", "k", "reflectance", m);
    } else if (pbrt_tok_eq(type, "dielectric") || pbrt_tok_eq(type, "thindielectric")) {
        double eta = 1.5;
        if ((st = pbrt_get_float_tex(p, lx, "eta", &eta))) return st;
        if (!(eta > 0)) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "eta"), "> 0");
        *m = material_dielectric((float)eta);
        if ((st = get_roughness(p, lx, m, 0))) return st;
        if (pbrt_tok_eq(type, "thindielectric")) m->flags |= MAT_THIN;
    } else if (pbrt_tok_eq(type, "coateddiffuse") || pbrt_tok_eq(type, "coatedconductor")) {
        st = make_coated(p, lx, pbrt_tok_eq(type, "coatedconductor"), m);
    } else if (pbrt_tok_eq(type, "interface") || pbrt_tok_eq(type, "") || pbrt_tok_eq(type, "none")) {
        /* an invisible boundary (a medium's edge), which rays pass straight through
         * (docs/media.md). pbrt-v4 makes no material for "" and "none" either
         * (MaterialHandle::Create), as pbrt-v4-scenes' clouds.pbrt uses: Material "" on
         * its medium's sphere. */
        *m = material_interface();
        st = ST_OK;
    } else if (pbrt_tok_eq(type, "mix")) {
        st = make_mix(p, lx, type, m);
    } else if (pbrt_tok_eq(type, "subsurface")) {
        st = make_subsurface(p, lx, type, m);
    } else {
        *m = material_diffuse(v3(0.5f, 0.5f, 0.5f));
        char key[96];
        snprintf(key, sizeof key, "Material %.*s", (int)(type->len > 40 ? 40 : type->len), type->text);
        st = warn_once(p, lx, type, key, "material \"%.*s\" is not supported; diffuse 0.5 is used",
                       (int)(type->len > 40 ? 40 : type->len), type->text);
        for (size_t i = 0; i < p->pl.n; i++) p->pl.p[i].used = 1;
    }
    if (st) return st;
    pbrt_param_find(p, "type");
    return pbrt_warn_unused(p, lx, what);
}

static Status set_material(Parser *p, uint index)
{
    p->g.material = index;
    p->g.area_material = NO_INDEX;
    return ST_OK;
}

/* Adds material m under the name `name` (a copy; the scene owns it) and records the
 * name for NamedMaterial; its index into *index. */
static Status add_named_material(Parser *p, const Token *name, Material m, uint *index)
{
    char *n = tok_copy(name);
    if (!n) return error_set(p->err, ST_INTERNAL, "out of memory");
    Status st = scene_add_material(p->s, n, m, index, p->err);
    free(n);
    if (st) return st;
    if (strmap_set(&p->named_material, name->text, name->len, *index))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    return ST_OK;
}

Status pbrt_material(Parser *p, Lexer *lx, const Token *kw, const Token *type)
{
    (void)kw;
    Status st = ST_OK;
    Material m;
    if ((st = make_material(p, lx, type, &m, "Material"))) return st;
    uint index;
    if ((st = scene_add_material(p->s, "", m, &index, p->err))) return st;
    return set_material(p, index);
}

Status pbrt_make_named_material(Parser *p, Lexer *lx, const Token *kw, const Token *name)
{
    (void)kw;
    Status st = ST_OK;
    const Token *type = NULL;
    if ((st = pbrt_get_string(p, lx, "type", &type))) return st;
    if (!type) return lex_error_at(lx, name, p->err, "MakeNamedMaterial needs \"string type\"");
    Material m;
    if ((st = make_material(p, lx, type, &m, "MakeNamedMaterial"))) return st;
    uint index;
    PPending *pd;
    if (strmap_find(&p->named_material, name->text, name->len, &index) && (pd = pending_of(p, index))) {
        /* used before: the placeholder and its area-light copies become this material */
        pd->defined = 1;
        for (size_t i = 0; i < p->n_area_pending; i++) {
            if (p->area_of_pending[i].base != index) continue;
            Material *a = &p->s->materials[p->area_of_pending[i].area];
            Material e = m;
            e.emission = a->emission;
            e.flags |= a->flags & MAT_TWO_SIDED;
            *a = e;
        }
        p->s->materials[index] = m;
        return ST_OK;
    }
    return add_named_material(p, name, m, &index);
}

Status pbrt_named_material(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token name;
    Status st = pbrt_expect_string(p, lx, "a quoted material name", &name);
    if (st) return st;
    uint32_t i;
    if (strmap_find(&p->named_material, name.text, name.len, &i)) return set_material(p, i);
    /* not defined yet: pbrt-v4 looks names up once the whole scene is read, so a
     * later MakeNamedMaterial (pbrt-v4-scenes' contemporary-bathroom.pbrt includes its
     * materials.pbrt at the end) defines it; a placeholder until then */
    if ((st = add_named_material(p, &name, material_diffuse(v3(0.5f, 0.5f, 0.5f)), &i))) return st;
    if (pbrt_grow((void **)&p->pending, &p->cap_pending, p->n_pending + 1, sizeof(PPending)))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    PPending *pd = &p->pending[p->n_pending++];
    pd->index = i;
    pd->defined = 0;
    snprintf(pd->where, sizeof pd->where, "%s:%u:%u: material '%.*s'", lx->path, name.line, name.col,
             (int)(name.len > 40 ? 40 : name.len), name.text);
    return set_material(p, i);
}

/* pbrt-v4's (u, v) mapping of 2D textures: (uscale u + udelta, vscale v + vdelta) of
 * clpt's surface coordinates; another `mapping` (spherical, cylindrical, planar) is a
 * warning and uv. */
static Status tex_uv_mapping(Parser *p, const Lexer *lx, Texture *t)
{
    double su = 1, sv = 1, du = 0, dv = 0;
    const Token *mapping = NULL;
    Status st;
    if ((st = pbrt_get_float(p, lx, "uscale", &su)) || (st = pbrt_get_float(p, lx, "vscale", &sv)) ||
        (st = pbrt_get_float(p, lx, "udelta", &du)) || (st = pbrt_get_float(p, lx, "vdelta", &dv)) ||
        (st = pbrt_get_string(p, lx, "mapping", &mapping)))
        return st;
    if (mapping && !pbrt_tok_eq(mapping, "uv") &&
        (st = warn_once(p, lx, mapping, "texture-mapping", "texture mapping \"%.*s\" is not supported; uv is used",
                        (int)(mapping->len > 40 ? 40 : mapping->len), mapping->text)))
        return st;
    const char *names[4] = { "uscale", "vscale", "udelta", "vdelta" };
    const double vals[4] = { su, sv, du, dv };
    for (int i = 0; i < 4; i++)
        if (!(fabs(vals[i]) <= TEXTURE_MAX_MAP_ENTRY))
            return lex_error_at(lx, &pbrt_param_find(p, names[i])->decl, p->err, "\"%s\" is %g; clpt takes texture "
                                "scales and offsets of at most %.0f in size", names[i], vals[i],
                                (double)TEXTURE_MAX_MAP_ENTRY);
    texture_set_scale_offset(t, (float)su, (float)sv, (float)du, (float)dv);
    return ST_OK;
}

/* Texel i of scene texture t as linear RGB. */
static vec3 texel_rgb(const Scene *s, const Texture *t, size_t i)
{
    if (t->flags & TEX_FLOAT) {
        float f[3];
        memcpy(f, s->texels + t->offset + 3 * i, sizeof f);
        return v3(f[0], f[1], f[2]);
    }
    uint c = s->texels[t->offset + i];
    float rgb[3];
    for (int k = 0; k < 3; k++) {
        rgb[k] = (float)((c >> (8 * k)) & 255u) / 255.0f;
        if (t->flags & TEX_SRGB) rgb[k] = k_srgb_to_linear(rgb[k]);
    }
    return v3(rgb[0], rgb[1], rgb[2]);
}

/* The mean colour of an image texture's texels. */
static vec3 image_mean(const Scene *s, const Texture *t)
{
    size_t n = (size_t)t->width * t->height;
    double sum[3] = { 0, 0, 0 };
    for (size_t i = 0; i < n; i++) {
        vec3 c = texel_rgb(s, t, i);
        sum[0] += c.x;
        sum[1] += c.y;
        sum[2] += c.z;
    }
    return n ? v3((float)(sum[0] / n), (float)(sum[1] / n), (float)(sum[2] / n)) : v3(0, 0, 0);
}

static Status tex_imagemap(Parser *p, const Lexer *lx, const Token *cls, PTexture *t)
{
    const Token *f = NULL, *enc = NULL;
    Status st;
    if ((st = pbrt_get_string(p, lx, "filename", &f))) return st;
    if (!f) return lex_error_at(lx, cls, p->err, "an imagemap texture needs \"string filename\"");
    if ((st = pbrt_get_string(p, lx, "encoding", &enc))) return st;
    int linear = enc && pbrt_tok_eq(enc, "linear");
    /* pbrt-v4's wrap: "repeat" (its default, and clpt's), "clamp" (clpt's clamp to the
     * edge); "black" and "octahedralsphere" a warning and repeat */
    const Token *wrap = NULL;
    if ((st = pbrt_get_string(p, lx, "wrap", &wrap))) return st;
    int clamp = wrap && pbrt_tok_eq(wrap, "clamp");
    if (wrap && !clamp && !pbrt_tok_eq(wrap, "repeat") &&
        (st = warn_once(p, lx, wrap, "texture-wrap", "texture wrap \"%.*s\" is not supported; repeat is used",
                        (int)(wrap->len > 40 ? 40 : wrap->len), wrap->text)))
        return st;
    char *path = pbrt_beside_main(p, f);
    if (!path) return error_set(p->err, ST_INTERNAL, "out of memory");
    st = texture_load_image(p->s, NULL, path, linear, clamp, &t->index, p->err);
    free(path);
    if (st) {
        reader_annotate(lx, f, p->err);
        return st;
    }
    t->constant = 0;
    Texture *tx = &p->s->textures[t->index];
    t->mean = image_mean(p->s, tx);
    return tex_uv_mapping(p, lx, tx);
}

/* A colour parameter that may name another texture (checkerboard's tex1 and tex2,
 * scale's tex and scale): a constant's value; a varying texture in *tex when `tex` is
 * not NULL, else its mean colour with a warning. */
static Status tex_operand(Parser *p, const Lexer *lx, const char *name, vec3 *out, const PTexture **tex)
{
    Param *pa = pbrt_param_find(p, name);
    if (tex) *tex = NULL;
    if (!pa) return ST_OK;
    if (pa->type != PT_TEXTURE) {
        pa->used = 0;
        return pbrt_get_spectrum(p, lx, name, out, NULL, NULL);
    }
    const Token *n = &p->pl.strs[pa->first];
    uint32_t i;
    if (!strmap_find(&p->tex_by_name, n->text, n->len, &i))
        return lex_error_at(lx, n, p->err, "texture '%.*s' is not defined", (int)(n->len > 40 ? 40 : n->len), n->text);
    const PTexture *src = &p->tex[i];
    if (src->constant) {
        *out = src->color;
    } else if (tex) {
        *tex = src;
    } else {
        *out = src->mean;
        return warn_once(p, lx, &pa->decl, "checker-texture", "a checkerboard's \"%.*s\" is a texture: its mean "
                         "colour is used", (int)pa->name_len, pa->name);
    }
    return ST_OK;
}

/* pbrt-v4's checkerboard: tex1 on the cells whose integer coordinates sum to an even
 * number (pbrt's weight 0.5 - bf(s) bf(t) / 2 is 0 there), tex2 on the others: clpt's
 * TEX_CHECKER colour0 and colour1. 2D on the surface's (u, v) mapped as tex_uv_mapping,
 * or 3D (dimension 3) at the point in the texture's space: the CTM at Texture maps
 * texture space to the world, as pbrt's PointTransformMapping. */
static Status tex_checkerboard(Parser *p, const Lexer *lx, PTexture *t)
{
    vec3 c1 = v3(1, 1, 1), c2 = v3(0, 0, 0);   /* pbrt's defaults */
    long dim = 2;
    Status st;
    if ((st = tex_operand(p, lx, "tex1", &c1, NULL)) || (st = tex_operand(p, lx, "tex2", &c2, NULL)) ||
        (st = pbrt_get_int(p, lx, "dimension", &dim)))
        return st;
    if (dim != 2 && dim != 3) return pbrt_param_type_error(p, lx, pbrt_param_find(p, "dimension"), "2 or 3");
    Texture tx = texture_make_checker(c1, c2, 1.0f, dim == 3);
    if (dim == 3) {
        int ok;
        Transform inv = transform_inverse(&p->g.ctm, &ok);
        if (!ok) return lex_error_at(lx, &pbrt_param_find(p, "dimension")->decl, p->err,
                                     "the checkerboard's transform cannot be inverted");
        float m[12];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 4; j++) m[4 * i + j] = (float)inv.m[i][j];
        texture_set_matrix(&tx, m);
        if ((st = texture_check_map(&tx, p->err))) {
            const Token *d = &pbrt_param_find(p, "dimension")->decl;
            error_prefix(p->err, "%s:%u:%u: the 3D checkerboard's transform", lx->path, d->line, d->col);
            return st;
        }
    } else if ((st = tex_uv_mapping(p, lx, &tx))) {
        return st;
    }
    t->constant = 0;
    t->mean = v3_scale(v3_add(c1, c2), 0.5f);
    return scene_add_texture(p->s, NULL, NULL, tx, &t->index, p->err);
}

/* A copy of varying texture src with every colour times k: a checkerboard with its two
 * colours scaled, an image as float texels scaled (the original stays for its other
 * users). */
static Status tex_scaled_copy(Parser *p, const PTexture *src, vec3 k, PTexture *out)
{
    Scene *s = p->s;
    Texture tx = s->textures[src->index];
    out->constant = 0;
    out->mean = v3_mul(src->mean, k);
    if (tx.type == TEX_CHECKER) {
        tx.color0 = v3_mul(tx.color0, k);
        tx.color1 = v3_mul(tx.color1, k);
        return scene_add_texture(s, NULL, NULL, tx, &out->index, p->err);
    }
    size_t n = (size_t)tx.width * tx.height;
    uint *texels = malloc(n * 3 * sizeof *texels);
    if (!texels) return error_set(p->err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < n; i++) {
        vec3 c = v3_mul(texel_rgb(s, &tx, i), k);
        float f[3] = { c.x, c.y, c.z };
        memcpy(texels + 3 * i, f, sizeof f);
    }
    Status st = scene_add_texels(s, texels, n * 3, &tx.offset, p->err);
    free(texels);
    if (st) return st;
    tx.flags = (tx.flags & ~TEX_SRGB) | TEX_FLOAT;
    return scene_add_texture(s, NULL, NULL, tx, &out->index, p->err);
}

/* pbrt-v4's scale: tex x scale. Two constants multiply; a varying texture times a
 * constant is a scaled copy of it; two varying ones, a warning: the first times the
 * second's mean colour. */
static Status tex_scale(Parser *p, const Lexer *lx, PTexture *t)
{
    vec3 a = v3(1, 1, 1), b = v3(1, 1, 1);
    const PTexture *ta, *tb;
    Status st;
    if ((st = tex_operand(p, lx, "tex", &a, &ta)) || (st = tex_operand(p, lx, "scale", &b, &tb))) return st;
    if (ta && tb) {
        if ((st = warn_once(p, lx, &pbrt_param_find(p, "scale")->decl, "scale-two", "a scale texture of two textures: "
                            "the second's mean colour scales the first")))
            return st;
        b = tb->mean;
        tb = NULL;
    }
    if (!ta && !tb) {
        t->color = v3_mul(a, b);
        return ST_OK;
    }
    return ta ? tex_scaled_copy(p, ta, b, t) : tex_scaled_copy(p, tb, a, t);
}

Status pbrt_texture(Parser *p, Lexer *lx, const Token *kw)
{
    (void)kw;
    Token name, vtype, cls;
    Status st = pbrt_expect_string(p, lx, "a quoted texture name", &name);
    if (!st) st = pbrt_expect_string(p, lx, "a quoted texture type (spectrum or float)", &vtype);
    if (!st) st = pbrt_expect_string(p, lx, "a quoted texture class", &cls);
    if (!st) st = pbrt_parse_params(p, lx);
    if (st) return st;
    PTexture t = {0};
    t.constant = 1;
    t.color = v3(1, 1, 1);
    t.index = NO_INDEX;
    if (pbrt_tok_eq(&cls, "constant")) {
        if ((st = pbrt_get_spectrum(p, lx, "value", &t.color, NULL, NULL))) return st;
    } else if (pbrt_tok_eq(&cls, "imagemap")) {
        st = tex_imagemap(p, lx, &cls, &t);
    } else if (pbrt_tok_eq(&cls, "checkerboard")) {
        st = tex_checkerboard(p, lx, &t);
    } else if (pbrt_tok_eq(&cls, "scale")) {
        st = tex_scale(p, lx, &t);
    } else {
        char key[96];
        snprintf(key, sizeof key, "Texture %.*s", (int)(cls.len > 40 ? 40 : cls.len), cls.text);
        st = warn_once(p, lx, &cls, key, "texture \"%.*s\" is not supported; it is a constant 1",
                       (int)(cls.len > 40 ? 40 : cls.len), cls.text);
        for (size_t i = 0; i < p->pl.n; i++) p->pl.p[i].used = 1;
    }
    if (st) return st;
    if (t.constant) t.mean = t.color;
    if (pbrt_grow((void **)&p->tex, &p->cap_tex, p->n_tex + 1, sizeof(PTexture)) ||
        strmap_set(&p->tex_by_name, name.text, name.len, (uint32_t)p->n_tex))
        return error_set(p->err, ST_INTERNAL, "out of memory");
    p->tex[p->n_tex++] = t;
    return pbrt_warn_unused(p, lx, "Texture");
}

/* The material of the next shape: the current one, with the area light's emission. */
Status pbrt_shape_material(Parser *p, uint *out)
{
    Status st;
    *out = NO_INDEX;
    if (p->g.material == NO_INDEX) {
        uint i;
        if ((st = scene_add_material(p->s, "", material_diffuse(v3(0.5f, 0.5f, 0.5f)), &i, p->err))) return st;
        p->g.material = i;
    }
    if (!p->g.area) return pbrt_shape_media(p, p->g.material, out);
    if (p->g.area_material == NO_INDEX) {
        Material m = p->s->materials[p->g.material];
        m.emission = p->g.area_L;
        if (p->g.area_twosided) m.flags |= MAT_TWO_SIDED;
        uint i;
        if ((st = scene_add_material(p->s, "", m, &i, p->err))) return st;
        p->g.area_material = i;
        if (pending_of(p, p->g.material)) {
            if (pbrt_grow((void **)&p->area_of_pending, &p->cap_area_pending, p->n_area_pending + 1,
                          sizeof *p->area_of_pending))
                return error_set(p->err, ST_INTERNAL, "out of memory");
            p->area_of_pending[p->n_area_pending].area = i;
            p->area_of_pending[p->n_area_pending++].base = p->g.material;
        }
    }
    return pbrt_shape_media(p, p->g.area_material, out);
}
