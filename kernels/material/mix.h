/*
 * mix.h — pbrt-v4's mix material (MAT_MIX): at each hit one of two materials scatters,
 * the second with probability `amount`, the first otherwise; over many hits that is the
 * blend amount × second + (1 − amount) × first, without a BSDF that holds both.
 *
 * The choice is made once per hit, before anything reads the material's lobes, normal
 * map or textured parameters, so next-event estimation and BSDF sampling at that hit
 * see the same material. As in pbrt (MixMaterial::ChooseMaterial hashes the point, wo
 * and the two materials) the coin is a hash, not a sampler dimension: of the hit point's
 * bits, the incoming direction's bits and the mix's index. Those are the same bits on
 * every device (the rays come from the counter-based sampler and the arithmetic has no
 * contractions), so the choice is too and images stay bit-identical across devices; the
 * sampler's dimension layout (rng.h) is unchanged. A nested mix chooses again with its
 * own index in the hash, at most MIX_MAX_DEPTH levels (the readers refuse deeper ones).
 *
 * What a mix emits and on which sides is its own (emission, MAT_TWO_SIDED): lights and
 * light sampling read the primitive's material as it is stored (lights.h), so the mix
 * carries the area light, not the materials it picks. Cut-outs (alpha.h) read the
 * stored material too: a mix's choices are never cut out.
 */
#ifndef CLPT_MIX_H
#define CLPT_MIX_H

#include "sample/rng.h"
#include "material/texture.h"

/* The coin of mix `index` at point p for a ray travelling along d: uniform in [0, 1). */
KFN float mix_uniform(vec3 p, vec3 d, uint index)
{
    uint h = rng_hash(k_as_uint(p.x) ^ 0x5bd1e995u);
    h = rng_hash(h ^ k_as_uint(p.y));
    h = rng_hash(h ^ k_as_uint(p.z));
    h = rng_hash(h ^ k_as_uint(d.x));
    h = rng_hash(h ^ k_as_uint(d.y));
    h = rng_hash(h ^ k_as_uint(d.z));
    h = rng_hash(h ^ index);
    return (float)(h >> 8) * 5.9604645e-8f;
}

/* The material that scatters at s for a ray travelling along d, in *m (material
 * s.material on entry): itself, or for a mix the one its coin picks (ng_face: the
 * geometric normal on the ray's side, for a solid texture's lookup of amount). In place,
 * because a Material is 176 bytes: copies of it returned by value were a tenth of the
 * time of shading a diffuse bounce on the scalar device. */
KFN void material_resolve(const SceneView *sc, Material *m, Surface s, vec3 d, vec3 ng_face)
{
    uint index = s.material;
    for (uint depth = 0u; m->type == MAT_MIX && depth < MIX_MAX_DEPTH; depth++) {
        float amount = m->mix_amount;
        if (m->mix_texture != NO_INDEX) amount *= texture_eval(sc, m->mix_texture, s, ng_face).x;
        index = mix_uniform(s.p, d, index) < amount ? m->mix_b : m->mix_a;
        *m = sc->materials[index];
    }
}

#endif /* CLPT_MIX_H */
