/* material.c — the material constructors and presets of scene.h: each type's defaults
 * in one place, for every reader. */
#include "scene/scene.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "util/kmath.h"

static Material material_base(uint type)
{
    Material m;
    memset(&m, 0, sizeof m);
    m.type = type;
    m.texture = NO_INDEX;
    m.texture_rm = NO_INDEX;
    m.texture_normal = NO_INDEX;
    m.normal_scale = 1.0f;
    m.ior = 1.5f;
    m.alpha = 1.0f;
    m.alpha_cutoff = 0.5f;      /* glTF's default alphaCutoff */
    m.texture_emission = NO_INDEX;
    m.mix_a = m.mix_b = m.mix_texture = NO_INDEX;
    m.specular_factor = 1.0f;   /* KHR_materials_specular's defaults: F0 and F90 as they were */
    m.specular_color = v3s(1.0f);
    m.texture_specular = m.texture_specular_color = NO_INDEX;
    m.texture_sheen_color = m.texture_sheen_roughness = NO_INDEX;
    m.diffuse_transmission_color = v3s(1.0f);  /* KHR_materials_diffuse_transmission's */
    m.texture_diffuse_transmission = m.texture_diffuse_transmission_color = NO_INDEX;
    return m;
}

Material material_diffuse(vec3 albedo)
{
    Material m = material_base(MAT_DIFFUSE);
    m.albedo = albedo;
    return m;
}

Material material_metal(vec3 albedo, float fuzz)
{
    Material m = material_base(MAT_METAL);
    m.albedo = albedo;
    m.fuzz = fuzz;
    return m;
}

Material material_dielectric(float ior)
{
    Material m = material_base(MAT_DIELECTRIC);
    m.albedo = v3s(1.0f);
    m.ior = ior;
    return m;
}

Material material_conductor(vec3 eta, vec3 k, float roughness)
{
    Material m = material_base(MAT_CONDUCTOR);
    m.albedo = v3s(1.0f);
    m.eta = eta;
    m.k = k;
    m.roughness = roughness;
    return m;
}

Material material_conductor_f0(vec3 f0, float roughness)
{
    Material m = material_conductor(v3s(1.0f), v3s(0.0f), roughness);
    m.specular = f0;
    m.flags |= MAT_F0;
    return m;
}

static Material material_layered(uint base, float roughness)
{
    Material m = material_base(MAT_LAYERED);
    m.layer_base = base;
    m.roughness = roughness;
    m.layer_thickness = 0.01f;
    m.layer_depth = 10;
    m.layer_samples = 1;
    return m;
}

Material material_coated_diffuse(vec3 diffuse, float roughness)
{
    Material m = material_layered(LAYER_BASE_DIFFUSE, roughness);
    m.albedo = diffuse;
    return m;
}

Material material_coated_conductor(vec3 eta, vec3 k, float base_roughness, float roughness)
{
    Material m = material_layered(LAYER_BASE_CONDUCTOR, roughness);
    m.albedo = v3s(1.0f);
    m.eta = eta;
    m.k = k;
    m.base_roughness = base_roughness;
    return m;
}

Material material_mix(uint a, uint b, float amount, uint amount_tex)
{
    Material m = material_base(MAT_MIX);
    m.mix_a = a;
    m.mix_b = b;
    m.mix_amount = amount;
    m.mix_texture = amount_tex;
    return m;
}

/* The depth of `index`'s mixes, entered `level` mixes deep: a cycle, or a chain deeper
 * than the kernels follow, stops at MIX_MAX_DEPTH + 1 (and so do the calls). */
static uint mix_depth(const Scene *s, uint index, uint level)
{
    if (index >= s->n_materials || level > MIX_MAX_DEPTH) return MIX_MAX_DEPTH + 1;
    const Material *m = &s->materials[index];
    if (m->type != MAT_MIX) return 0;
    uint a = mix_depth(s, m->mix_a, level + 1);
    uint b = a > MIX_MAX_DEPTH ? a : mix_depth(s, m->mix_b, level + 1);
    uint deepest = a > b ? a : b;
    return deepest > MIX_MAX_DEPTH ? deepest : deepest + 1;
}

uint scene_mix_depth(const Scene *s, uint index) { return mix_depth(s, index, 0); }

Material material_principled(vec3 base, float metallic, float roughness)
{
    Material m = material_base(MAT_PRINCIPLED);
    m.albedo = base;
    m.metallic = metallic;
    m.roughness = roughness;
    return m;
}

/* -ln(color) / distance per channel. A channel of 0 (all absorbed) is taken as the
 * smallest normal float, so sigma_a stays finite (exp(-sigma_a 0) must still be 1). */
static float absorption_channel(float color, float distance)
{
    float c = color < FLT_MIN ? FLT_MIN : (color > 1.0f ? 1.0f : color);
    return isinf(distance) ? 0.0f : -logf(c) / distance;
}

vec3 material_absorption(vec3 color, float distance)
{
    return v3(absorption_channel(color.x, distance), absorption_channel(color.y, distance),
              absorption_channel(color.z, distance));
}

/* Measured spectra interpolated at 650, 550 and 450 nm for R, G and B: Ag, Al, Au, Cu
 * from pbrt-v4 (src/pbrt/util/spectrum.cpp, after refractiveindex.info), Cr and Ni from
 * Mitsuba 0.6 (data/ior/Cr.*.spd, Ni_palik.*.spd: the luxpop database, Palik's
 * Handbook of Optical Constants of Solids), Fe and Ti from Johnson & Christy, Phys.
 * Rev. B 9, 5056 (1974), as tabulated by refractiveindex.info (data-nk/main/Fe/Johnson.yml,
 * Ti/Johnson.yml; linear in wavelength between its samples). */
static const struct {
    const char *name;
    float eta[3], k[3];
} metal_presets[] = {
    {"Ag", {0.1394f, 0.1248f, 0.1517f}, {4.1288f, 3.3396f, 2.4704f}},
    {"Al", {1.4748f, 0.9586f, 0.6180f}, {7.7941f, 6.6870f, 5.4694f}},
    {"Au", {0.1678f, 0.3504f, 1.5085f}, {3.1378f, 2.7141f, 1.8788f}},
    {"Cr", {3.6375f, 3.1158f, 1.9277f}, {4.3644f, 4.4228f, 4.1675f}},
    {"Cu", {0.2166f, 0.9582f, 1.1658f}, {3.6377f, 2.5771f, 2.3939f}},
    {"Fe", {2.9114f, 2.9497f, 2.5845f}, {3.0893f, 2.9318f, 2.7670f}},
    {"Ni", {2.0140f, 1.7724f, 1.6288f}, {3.8079f, 3.2526f, 2.6540f}},
    {"Ti", {2.7407f, 2.5418f, 2.2670f}, {3.8143f, 3.4345f, 3.0385f}},
};

int material_metal_preset(const char *name, size_t len, vec3 *eta, vec3 *k)
{
    for (size_t i = 0; i < sizeof metal_presets / sizeof metal_presets[0]; i++) {
        if (strlen(metal_presets[i].name) != len || memcmp(metal_presets[i].name, name, len) != 0) continue;
        *eta = v3(metal_presets[i].eta[0], metal_presets[i].eta[1], metal_presets[i].eta[2]);
        *k = v3(metal_presets[i].k[0], metal_presets[i].k[1], metal_presets[i].k[2]);
        return 1;
    }
    return 0;
}

Material material_emissive(vec3 radiance)
{
    Material m = material_base(MAT_EMISSIVE);
    m.emission = radiance;
    return m;
}

Material material_phong(vec3 diffuse, vec3 specular, float shininess)
{
    Material m = material_base(MAT_PHONG);
    m.albedo = diffuse;
    m.specular = specular;
    m.shininess = shininess;
    m.ior = 1.0f;
    return m;
}
