/* texel_pack.c — float textures as RGBE words where exact (see texel_pack.h). */
#include "scene/texel_pack.h"

#include <stdlib.h>
#include <string.h>

/* On the float bits, not through frexpf and ldexpf: a map has half a million texels, and
 * with the library calls (and a second pass) packing one took 427 million instructions,
 * now 82 million (cachegrind, envmap.scene). A component 1.f x 2^(e - 127)
 * is the mantissa q = 1.f x 2^(e + 7 - em) under the exponent em + 2 of the largest
 * component (em its exponent bits), an integer exactly when the bits shifted out are 0. */
int rgbe_encode_exact(const float c[3], uint *word)
{
    uint b[3], m = 0;
    memcpy(b, c, sizeof b);
    for (int i = 0; i < 3; i++) {
        if ((b[i] >> 31) || (b[i] & 0x7f800000u) == 0x7f800000u) return 0; /* negative, -0, inf, NaN */
        if (b[i] > m) m = b[i];
    }
    if (m == 0) {
        *word = 10u << 24;
        return 1;
    }
    uint em = m >> 23;
    if (em < 8u || em > 253u) return 0; /* the exponent em + 2 must lie in [10, 255] */
    uint w = (em + 2u) << 24;
    for (int i = 0; i < 3; i++) {
        if (b[i] == 0) continue;
        uint ec = b[i] >> 23;
        if (ec == 0 || ec + 7u < em) return 0; /* subnormal, or below the last mantissa bit */
        uint shift = 23u - (ec + 7u - em), sig = 0x800000u | (b[i] & 0x7fffffu);
        if (sig & ((1u << shift) - 1u)) return 0;
        w |= (sig >> shift) << (8 * i);
    }
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

/* The words the textures refs[a..b) (one offset, the largest of them) need as they are;
 * b is set past the last texture at that offset. */
static size_t group_words(const Scene *s, const TexRef *refs, size_t a, size_t n, size_t *b)
{
    size_t need = 0, k = a;
    for (; k < n && refs[k].offset == refs[a].offset; k++) {
        size_t w = texture_words(&s->textures[refs[k].index]);
        if (w > need) need = w;
    }
    *b = k;
    return need;
}

/* Writes the RGBE words of the textures refs[0..n) (one offset) to out and returns 1
 * when they are float images of one size, not yet packed, whose texels all have exact
 * RGBE words; else 0, and out holds nothing of use. */
static int group_pack(const Scene *s, const TexRef *refs, size_t n, uint *out)
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
        memcpy(c, in + 3u * i, sizeof c);
        if (!rgbe_encode_exact(c, &out[i])) return 0;
    }
    return 1;
}

Status scene_pack_texels(Scene *s, Error *err)
{
    /* most scenes have no float image to pack: leave their texels alone */
    size_t n = 0, candidates = 0;
    for (size_t i = 0; i < s->n_textures; i++) {
        const Texture *t = &s->textures[i];
        n += t->type == TEX_IMAGE;
        candidates += t->type == TEX_IMAGE && (t->flags & (TEX_FLOAT | TEX_RGBE)) == TEX_FLOAT;
    }
    if (candidates == 0) return ST_OK;
    TexRef *refs = malloc(n * sizeof *refs);
    if (!refs) return error_set(err, ST_INTERNAL, "out of memory packing the textures");
    n = 0;
    for (size_t i = 0; i < s->n_textures; i++)
        if (s->textures[i].type == TEX_IMAGE) refs[n++] = (TexRef){ s->textures[i].offset, (uint)i };
    qsort(refs, n, sizeof *refs, ref_cmp);

    /* room for every region as it is (packing only shrinks one) */
    size_t words = 0;
    for (size_t a = 0, b; a < n; a = b) {
        size_t need = group_words(s, refs, a, n, &b);
        if (refs[a].offset > s->n_texels || need > s->n_texels - refs[a].offset) {
            uint bad = refs[a].index;
            free(refs);
            return error_set(err, ST_INTERNAL, "texture %u reads past the texels", bad);
        }
        words += need;
    }
    uint *out = malloc((words ? words : 1u) * sizeof *out);
    if (!out) {
        free(refs);
        return error_set(err, ST_INTERNAL, "out of memory packing the textures");
    }
    size_t len = 0;
    for (size_t a = 0, b; a < n; a = b) {
        size_t need = group_words(s, refs, a, n, &b);
        int packs = group_pack(s, refs + a, b - a, out + len);
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
    /* give back the room the packed regions did not use (two thirds of each) */
    uint *fit = len ? realloc(out, len * sizeof *out) : NULL;
    if (fit) out = fit;
    free(s->texels);
    s->texels = out;
    s->n_texels = len;
    s->cap_texels = fit ? len : (words ? words : 1u);
    return ST_OK;
}
