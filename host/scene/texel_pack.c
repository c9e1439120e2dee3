/* texel_pack.c — float textures as RGBE words where exact (see texel_pack.h). */
#include "scene/texel_pack.h"

#include "texture.h" /* rgbe_decode: a word is checked by the kernels' own decoding */

#include <math.h>
#include <stdlib.h>
#include <string.h>

int rgbe_encode_exact(const float c[3], uint *word)
{
    float m = 0.0f;
    for (int i = 0; i < 3; i++) {
        if (!(c[i] >= 0.0f) || !isfinite(c[i]) || signbit(c[i])) return 0;
        if (c[i] > m) m = c[i];
    }
    int e = 0;
    if (m > 0.0f) frexpf(m, &e); /* m = f 2^e, f in [0.5, 1) */
    /* the largest mantissa m / 2^(E - 136) = f 2^8 lies in [128, 256) */
    int E = m > 0.0f ? e + 128 : 10;
    if (E < 10 || E > 255) return 0;
    uint w = (uint)E << 24;
    for (int i = 0; i < 3; i++) {
        float q = ldexpf(c[i], 136 - E);
        if (!(q <= 255.0f) || q != floorf(q)) return 0;
        w |= (uint)q << (8 * i);
    }
    vec3 d = rgbe_decode(w);
    float back[3] = { d.x, d.y, d.z };
    if (memcmp(back, c, sizeof back) != 0) return 0;
    *word = w;
    return 1;
}

typedef struct {
    uint offset, index;
} TexRef;

static int ref_cmp(const void *a, const void *b)
{
    const TexRef *x = a, *y = b;
    if (x->offset != y->offset) return x->offset < y->offset ? -1 : 1;
    return x->index < y->index ? -1 : (x->index > y->index);
}

/* The words of texture t's texels. */
static size_t texture_words(const Texture *t)
{
    size_t n = (size_t)t->width * t->height;
    return (t->flags & TEX_FLOAT) && !(t->flags & TEX_RGBE) ? 3u * n : n;
}

/* Whether the textures refs[0..n) (one offset) are float images of one size, not yet
 * packed, whose texels all have exact RGBE words; with `out`, writes them there. */
static int group_packs(const Scene *s, const TexRef *refs, size_t n, uint *out)
{
    const Texture *t0 = &s->textures[refs[0].index];
    for (size_t k = 0; k < n; k++) {
        const Texture *t = &s->textures[refs[k].index];
        if ((t->flags & (TEX_FLOAT | TEX_RGBE)) != TEX_FLOAT || t->width != t0->width || t->height != t0->height)
            return 0;
    }
    size_t texels = (size_t)t0->width * t0->height;
    const uint *in = s->texels + t0->offset;
    for (size_t i = 0; i < texels; i++) {
        float c[3];
        uint w;
        memcpy(c, in + 3u * i, sizeof c);
        if (!rgbe_encode_exact(c, &w)) return 0;
        if (out) out[i] = w;
    }
    return 1;
}

Status scene_pack_texels(Scene *s, Error *err)
{
    size_t n = 0;
    for (size_t i = 0; i < s->n_textures; i++) n += s->textures[i].type == TEX_IMAGE;
    if (n == 0) return ST_OK;
    TexRef *refs = malloc(n * sizeof *refs);
    if (!refs) return error_set(err, ST_INTERNAL, "out of memory packing the textures");
    n = 0;
    for (size_t i = 0; i < s->n_textures; i++)
        if (s->textures[i].type == TEX_IMAGE) refs[n++] = (TexRef){ s->textures[i].offset, (uint)i };
    qsort(refs, n, sizeof *refs, ref_cmp);

    /* first the new size (and whether anything packs at all), then the copy */
    size_t words = 0;
    int any = 0;
    for (size_t a = 0, b; a < n; a = b) {
        size_t need = 0;
        for (b = a; b < n && refs[b].offset == refs[a].offset; b++) {
            size_t w = texture_words(&s->textures[refs[b].index]);
            if (w > need) need = w;
        }
        if (refs[a].offset > s->n_texels || need > s->n_texels - refs[a].offset) {
            uint bad = refs[a].index;
            free(refs);
            return error_set(err, ST_INTERNAL, "texture %u reads past the texels", bad);
        }
        int packs = group_packs(s, refs + a, b - a, NULL);
        any |= packs;
        words += packs ? (size_t)s->textures[refs[a].index].width * s->textures[refs[a].index].height : need;
    }
    if (!any) {
        free(refs);
        return ST_OK;
    }
    uint *out = malloc((words ? words : 1u) * sizeof *out);
    if (!out) {
        free(refs);
        return error_set(err, ST_INTERNAL, "out of memory packing the textures");
    }
    size_t len = 0;
    for (size_t a = 0, b; a < n; a = b) {
        size_t need = 0;
        for (b = a; b < n && refs[b].offset == refs[a].offset; b++) {
            size_t w = texture_words(&s->textures[refs[b].index]);
            if (w > need) need = w;
        }
        int packs = group_packs(s, refs + a, b - a, out + len);
        if (packs)
            need = (size_t)s->textures[refs[a].index].width * s->textures[refs[a].index].height;
        else
            memcpy(out + len, s->texels + refs[a].offset, need * sizeof *out);
        for (size_t k = a; k < b; k++) {
            Texture *t = &s->textures[refs[k].index];
            t->offset = (uint)len;
            if (packs) t->flags |= TEX_RGBE;
        }
        len += need;
    }
    free(refs);
    free(s->texels);
    s->texels = out;
    s->n_texels = len;
    s->cap_texels = words ? words : 1u;
    return ST_OK;
}
