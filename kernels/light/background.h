/*
 * background.h — the radiance that reaches along a ray which escapes the scene: a
 * constant colour, a sky gradient, a cube map (the MIT 6.837 course's `cubeMap DIR`,
 * docs/classic-format.md) or an environment map (envmap.h). Both integrators call
 * background_radiance where a ray misses every primitive. Only the environment map is
 * also a light that next-event estimation samples (lights.h), so the path tracer weights
 * what its BSDF-sampled rays see of it by MIS (shade_path.h); the other backgrounds count
 * fully where a ray escapes. The path tracer never sees BG_CUBEMAP: the host resamples
 * a cube map into an environment map for it (host/scene/cube_env.c, which runs
 * cubemap_lookup below on the host); the Whitted integrator looks the faces up here.
 *
 * The cube map follows the course's CubeMap::getTexel exactly: the face is the axis of
 * the direction's largest component (x before y before z on ties), and the two other
 * components divided by it give the face's (u, v) in [0, 1], with the flips the course
 * chose per face:
 *
 *   +x right  u = (z/x + 1)/2        v = (y/x + 1)/2
 *   -x left   u = (z/x + 1)/2        v = 1 - (y/x + 1)/2
 *   +y up     u = (x/y + 1)/2        v = (z/y + 1)/2
 *   -y down   u = 1 - (x/y + 1)/2    v = 1 - (z/y + 1)/2
 *   +z front  u = 1 - (x/z + 1)/2    v = (y/z + 1)/2
 *   -z back   u = (x/z + 1)/2        v = 1 - (y/z + 1)/2
 *
 * and its getFaceTexel: x = u*width, y = (1 - v)*height (v = 1 is the image's first row),
 * bilinear between texels (floor(x), floor(y)) and the next ones, indices clamped to the
 * image: texel corners at integer coordinates, as the course's code has them (not the
 * texel centres of texture_image). Texels are the file's bytes / 255: no sRGB decoding.
 * Valid C11 and OpenCL C 1.2.
 */
#ifndef CLPT_BACKGROUND_H
#define CLPT_BACKGROUND_H

#include "light/envmap.h"
#include "material/texture.h"

/* Face texel (i, j) with both indices clamped to the image (i, j may be -1 .. size). */
KFN vec3 cubemap_texel(const SceneView *sc, Texture tx, float i, float j)
{
    uint x = (uint)k_clamp(i, 0.0f, (float)tx.width - 1.0f);
    uint y = (uint)k_clamp(j, 0.0f, (float)tx.height - 1.0f);
    return texel_fetch(sc, tx, x, y);
}

/* The colour of face `face` at (u, v), bilinear as the course's getFaceTexel. */
KFN vec3 cubemap_face(const SceneView *sc, uint face, float u, float v)
{
    Texture tx = sc->textures[sc->params->bg_cubemap + face];
    /* the ratios are within [-1, 1] for finite directions; NaN (an infinite component)
     * goes to the edge instead of an undefined conversion */
    u = u >= 0.0f ? (u <= 1.0f ? u : 1.0f) : 0.0f;
    v = v >= 0.0f ? (v <= 1.0f ? v : 1.0f) : 0.0f;
    float x = u * (float)tx.width, y = (1.0f - v) * (float)tx.height;
    float x0 = k_floor(x), y0 = k_floor(y);
    float a = x - x0, b = y - y0;
    vec3 top = v3_add(v3_scale(cubemap_texel(sc, tx, x0, y0), 1.0f - a),
                      v3_scale(cubemap_texel(sc, tx, x0 + 1.0f, y0), a));
    vec3 bot = v3_add(v3_scale(cubemap_texel(sc, tx, x0, y0 + 1.0f), 1.0f - a),
                      v3_scale(cubemap_texel(sc, tx, x0 + 1.0f, y0 + 1.0f), a));
    return v3_add(v3_scale(top, 1.0f - b), v3_scale(bot, b));
}

/* The cube map's colour along direction d (any length; black for the zero vector). */
KFN vec3 cubemap_lookup(const SceneView *sc, vec3 d)
{
    float ax = k_fabs(d.x), ay = k_fabs(d.y), az = k_fabs(d.z);
    if (ax >= ay && ax >= az) {
        if (d.x > 0.0f) return cubemap_face(sc, CUBE_RIGHT, (d.z / d.x + 1.0f) * 0.5f, (d.y / d.x + 1.0f) * 0.5f);
        if (d.x < 0.0f)
            return cubemap_face(sc, CUBE_LEFT, (d.z / d.x + 1.0f) * 0.5f, 1.0f - (d.y / d.x + 1.0f) * 0.5f);
    } else if (ay >= ax && ay >= az) {
        if (d.y > 0.0f) return cubemap_face(sc, CUBE_UP, (d.x / d.y + 1.0f) * 0.5f, (d.z / d.y + 1.0f) * 0.5f);
        if (d.y < 0.0f)
            return cubemap_face(sc, CUBE_DOWN, 1.0f - (d.x / d.y + 1.0f) * 0.5f, 1.0f - (d.z / d.y + 1.0f) * 0.5f);
    } else if (az >= ax && az >= ay) {
        if (d.z > 0.0f)
            return cubemap_face(sc, CUBE_FRONT, 1.0f - (d.x / d.z + 1.0f) * 0.5f, (d.y / d.z + 1.0f) * 0.5f);
        if (d.z < 0.0f)
            return cubemap_face(sc, CUBE_BACK, (d.x / d.z + 1.0f) * 0.5f, 1.0f - (d.y / d.z + 1.0f) * 0.5f);
    }
    return v3s(0.0f);
}

/* Radiance arriving along an escaping ray of direction d. */
KFN vec3 background_radiance(const SceneView *sc, vec3 d)
{
    GLOBAL const RenderParams *p = sc->params;
    if (KF_HAS(KF_CUBEMAP) && p->bg_type == BG_CUBEMAP) return cubemap_lookup(sc, d);
    if (KF_HAS(KF_ENV_MAP) && p->bg_type == BG_MAP) return env_radiance(sc, d);
    if (p->bg_type == BG_SKY) {
        float t = 0.5f * (d.y + 1.0f);
        return v3_add(v3_scale(p->bg_color, 1.0f - t), v3_scale(p->bg_zenith, t));
    }
    return p->bg_color;
}

#endif /* CLPT_BACKGROUND_H */
