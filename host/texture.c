/* texture.c — image and checkerboard textures (see texture.h). */
#include "texture.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb_image.h>

static Texture texture_base(uint type)
{
    Texture t;
    memset(&t, 0, sizeof t);
    t.type = type;
    t.m[0] = 1.0f;
    t.m[5] = 1.0f;
    t.m[10] = 1.0f;
    return t;
}

Texture texture_make_checker(vec3 c0, vec3 c1, float scale, int solid)
{
    Texture t = texture_base(TEX_CHECKER);
    t.flags = solid ? TEX_SOLID : 0u;
    t.color0 = c0;
    t.color1 = c1;
    texture_set_scale_offset(&t, scale, scale, 0.0f, 0.0f);
    return t;
}

void texture_set_scale_offset(Texture *t, float su, float sv, float ou, float ov)
{
    memset(t->m, 0, sizeof t->m);
    t->m[0] = su;
    t->m[3] = ou;
    t->m[5] = sv;
    t->m[7] = ov;
    t->m[10] = (t->flags & TEX_SOLID) ? su : 1.0f;
}

void texture_set_matrix(Texture *t, const float m[12])
{
    memcpy(t->m, m, sizeof t->m);
}

/* Packs 8-bit RGBA into the uint texel layout of kernels/texture.h. */
static uint pack_rgba(const unsigned char *p)
{
    return (uint)p[0] | (uint)p[1] << 8 | (uint)p[2] << 16 | (uint)p[3] << 24;
}

Status texture_load_image(Scene *s, const char *name, const char *path, int linear, int clamp,
                          uint *index, Error *err)
{
    Texture t = texture_base(TEX_IMAGE);
    uint encoding = linear ? 0u : TEX_SRGB;
    /* the same file read before with the same encoding: share its texels */
    for (size_t i = 0; i < s->n_textures; i++) {
        const Texture *o = &s->textures[i];
        if (!s->texture_sources[i] || strcmp(s->texture_sources[i], path) != 0) continue;
        if ((o->flags & TEX_FLOAT) == 0 && (o->flags & TEX_SRGB) != encoding) continue;
        t.offset = o->offset;
        t.width = o->width;
        t.height = o->height;
        t.flags = (o->flags & (TEX_FLOAT | TEX_SRGB)) | (clamp ? TEX_CLAMP : 0u);
        return scene_add_texture(s, name, path, t, index, err);
    }

    FILE *f = fopen(path, "rb");
    if (!f) return error_set(err, ST_IO, "cannot open '%s': %s", path, strerror(errno));
    fclose(f);
    int w = 0, h = 0, channels = 0;
    uint *texels = NULL;
    size_t n = 0;
    if (stbi_is_hdr(path)) {
        float *data = stbi_loadf(path, &w, &h, &channels, 3);
        if (!data)
            return error_set(err, ST_INPUT, "'%s': not an image stb_image can read (%s)", path,
                             stbi_failure_reason());
        n = (size_t)w * (size_t)h * 3u;
        texels = malloc(n * sizeof *texels);
        if (texels) memcpy(texels, data, n * sizeof *texels);   /* float bits as uint */
        stbi_image_free(data);
        t.flags = TEX_FLOAT;
    } else {
        unsigned char *data = stbi_load(path, &w, &h, &channels, 4);
        if (!data)
            return error_set(err, ST_INPUT, "'%s': not an image stb_image can read (%s)", path,
                             stbi_failure_reason());
        n = (size_t)w * (size_t)h;
        texels = malloc(n * sizeof *texels);
        if (texels)
            for (size_t i = 0; i < n; i++) texels[i] = pack_rgba(data + 4 * i);
        stbi_image_free(data);
        t.flags = encoding;
    }
    if (!texels) return error_set(err, ST_INTERNAL, "out of memory reading '%s'", path);
    if (w <= 0 || h <= 0) {
        free(texels);
        return error_set(err, ST_INPUT, "'%s': the image is empty", path);
    }
    uint offset;
    Status st = scene_add_texels(s, texels, n, &offset, err);
    free(texels);
    if (st) return st;
    t.offset = offset;
    t.width = (uint)w;
    t.height = (uint)h;
    if (clamp) t.flags |= TEX_CLAMP;
    return scene_add_texture(s, name, path, t, index, err);
}
