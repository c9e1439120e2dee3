/* cube_env.c — a cube map resampled into an environment map (see cube_env.h). */
#include "scene/cube_env.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "light/background.h"

/* Points per texel side whose lookups a texel averages. */
#define CUBE_ENV_SUB 3u

uint cube_env_height(uint face)
{
    uint h = face <= CUBE_ENV_MAX_HEIGHT / 2u ? 2u * face : CUBE_ENV_MAX_HEIGHT;
    return h < CUBE_ENV_MIN_HEIGHT ? CUBE_ENV_MIN_HEIGHT : h;
}

/* The longest side among the six faces starting at texture `first`. */
static uint cube_env_face_size(const Scene *s, uint first)
{
    uint size = 1u;
    for (uint f = 0; f < 6u; f++) {
        const Texture *t = &s->textures[first + f];
        if (t->width > size) size = t->width;
        if (t->height > size) size = t->height;
    }
    return size;
}

/* Texel (i, j) of a W x H map: the mean, in double so that a uniform face gives its
 * value back exactly, of the cube map along the directions of the sub-texel points
 * (envmap.h: phi = 2 pi u, theta = pi v, direction (sin t sin p, cos t, -sin t cos p)). */
static void cube_env_texel(const SceneView *v, uint i, uint j, uint W, uint H, float out[3])
{
    double acc[3] = { 0.0, 0.0, 0.0 };
    for (uint b = 0; b < CUBE_ENV_SUB; b++)
        for (uint a = 0; a < CUBE_ENV_SUB; a++) {
            double u = ((double)i + ((double)a + 0.5) / CUBE_ENV_SUB) / (double)W;
            double t = ((double)j + ((double)b + 0.5) / CUBE_ENV_SUB) / (double)H;
            double st = sin(M_PI * t), ct = cos(M_PI * t), sp = sin(2.0 * M_PI * u), cp = cos(2.0 * M_PI * u);
            vec3 c = cubemap_lookup(v, v3((float)(st * sp), (float)ct, (float)(-st * cp)));
            acc[0] += (double)c.x;
            acc[1] += (double)c.y;
            acc[2] += (double)c.z;
        }
    for (int k = 0; k < 3; k++) out[k] = (float)(acc[k] / (double)(CUBE_ENV_SUB * CUBE_ENV_SUB));
}

/* Fills the W x H map's texels (3 floats as uint bits each) from the cube map. */
static void cube_env_fill(const Scene *s, uint W, uint H, uint *texels)
{
    RenderParams p;
    memset(&p, 0, sizeof p);
    p.bg_type = BG_CUBEMAP;
    p.bg_cubemap = s->bg_cubemap;
    SceneView v;
    memset(&v, 0, sizeof v);
    v.params = &p;
    v.textures = s->textures;
    v.texels = s->texels;
    for (uint j = 0; j < H; j++)
        for (uint i = 0; i < W; i++) {
            float c[3];
            cube_env_texel(&v, i, j, W, H, c);
            memcpy(texels + 3u * ((size_t)j * W + i), c, sizeof c);
        }
}

Status cube_env_convert(Scene *s, Error *err)
{
    uint H = cube_env_height(cube_env_face_size(s, s->bg_cubemap)), W = 2u * H;
    size_t n = 3u * (size_t)W * H;
    uint *texels = malloc(n * sizeof *texels);
    if (!texels) return error_set(err, ST_INTERNAL, "out of memory resampling the cube map");
    cube_env_fill(s, W, H, texels);
    Status st = scene_set_envmap_texels(s, texels, W, H, 1.0f, err);
    free(texels);
    return st;
}
