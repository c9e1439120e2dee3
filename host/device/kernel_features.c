/* kernel_features.c — which kernel code a scene needs (see kernel_features.h). */
#include "device/kernel_features.h"

unsigned kernel_params_features(const RenderParams *p)
{
    return (p->bg_type == BG_MAP ? KF_ENV_MAP : 0u) | (p->bg_type == BG_CUBEMAP ? KF_CUBEMAP : 0u) |
           (p->has_media ? KF_MEDIA : 0u);
}

unsigned kernel_scene_features(const DeviceScene *s)
{
    const RenderParams *p = &s->params;
    unsigned f = kernel_params_features(p);
    for (uint i = 0; i < s->n_materials; i++) {
        const Material *m = &s->materials[i];
        /* a mix (kernels/material/mix.h, always compiled) scatters as the materials it picks,
         * which are in this list themselves; only its amount texture is its own */
        if (m->type == MAT_MIX) {
            if (m->mix_texture != NO_INDEX) f |= KF_TEXTURES;
            continue;
        }
        f |= material_feature(m->type);
        /* a subsurface walk leaves its solid as a white diffuse surface (shade_path.h) */
        if (m->type == MAT_PRINCIPLED && m->subsurface > 0.0f) f |= material_feature(MAT_DIFFUSE);
        if (m->texture != NO_INDEX || m->texture_emission != NO_INDEX || m->texture_rm != NO_INDEX ||
            m->texture_normal != NO_INDEX || m->texture_specular != NO_INDEX ||
            m->texture_specular_color != NO_INDEX || m->texture_sheen_color != NO_INDEX ||
            m->texture_sheen_roughness != NO_INDEX || m->texture_diffuse_transmission != NO_INDEX ||
            m->texture_diffuse_transmission_color != NO_INDEX)
            f |= KF_TEXTURES;
        if (m->flags & MAT_ALPHA_ANY) f |= KF_ALPHA;
    }
    for (uint i = 0; i < p->n_lights; i++) f |= light_feature(s->lights[i].type);
    f |= (p->n_spheres ? KF_SPHERES : 0u) | (p->n_boxes ? KF_BOXES : 0u) | (p->n_planes ? KF_PLANES : 0u) |
         (p->n_revsurfaces ? KF_REVSURFACE : 0u) | (p->n_bvh_nodes ? KF_BVH : KF_KDTREE) |
         /* --accel kdtree with instances: the BVH's top level over kd-tree prototypes */
         (p->n_instances ? KF_BVH : 0u) |
         (s->n_sphere_xforms ? KF_SPHERE_XFORM : 0u) | (p->n_instances ? KF_INSTANCES : 0u) |
         (p->camera.moving ? KF_MOTION : 0u);
    return f;
}

int kernel_lanes_scene(const DeviceScene *s, unsigned features)
{
    const RenderParams *p = &s->params;
    /* no other material type, primitive, texture, background map or delta light */
    unsigned plain = KF_MATERIAL(MAT_DIFFUSE) | KF_MATERIAL(MAT_EMISSIVE) | KF_KDTREE | KF_BVH;
    if ((features & ~plain) != 0u || s->n_shading != 0u || p->n_triangles == 0u || p->n_lights == 0u) return 0;
    for (uint i = 0; i < s->n_materials; i++) {
        const Material *m = &s->materials[i];
        if (m->type == MAT_DIFFUSE && (m->emission.x != 0.0f || m->emission.y != 0.0f || m->emission.z != 0.0f))
            return 0;
    }
    for (uint i = 0; i < p->n_lights; i++) {
        const Light *l = &s->lights[i];
        if (l->type != LIGHT_AREA || l->prim < p->n_spheres || l->prim - p->n_spheres >= p->n_triangles) return 0;
    }
    return 1;
}

int kernel_lanes_params(const RenderParams *p)
{
    /* --clamp: the float8 light sample does not clamp; k_path does */
    return p->sampler == SAMPLER_SOBOL && p->mis_mode == MIS_BOTH && p->shadows && !(p->clamp_indirect > 0.0f);
}
