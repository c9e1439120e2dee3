/* texture_util.h — an image texture made from texels in memory, for the tests that need
 * one (the loaders make theirs from files). */
#ifndef CLPT_TEXTURE_UTIL_H
#define CLPT_TEXTURE_UTIL_H

#include "io/texture.h"
#include "scene/scene.h"

/* Appends a w x h image texture of `words` (3 a texel with TEX_FLOAT, else one packed
 * RGBA8) with `flags`, mapped as (u, v) itself; returns its index, or NO_INDEX when
 * the scene refuses it. */
static inline uint test_image_texture(Scene *s, const uint *words, uint w, uint h, uint flags)
{
    uint offset, index;
    size_t n = (size_t)w * h * ((flags & TEX_FLOAT) ? 3u : 1u);
    if (scene_add_texels(s, words, n, &offset, NULL) != ST_OK) return NO_INDEX;
    Texture t = texture_make_checker(v3s(0.0f), v3s(0.0f), 1.0f, 0);
    t.type = TEX_IMAGE;
    t.flags = flags;
    t.offset = offset;
    t.width = w;
    t.height = h;
    texture_set_scale_offset(&t, 1.0f, 1.0f, 0.0f, 0.0f);
    return scene_add_texture(s, NULL, NULL, t, &index, NULL) == ST_OK ? index : NO_INDEX;
}

#endif /* CLPT_TEXTURE_UTIL_H */
