/*
 * texture.h — the colour of a texture at a surface point: image textures (bilinear,
 * sRGB-decoded, repeat or clamp) and checkerboards (solid, or on the surface's (u, v)).
 *
 * Surface coordinates: triangles use their texture coordinates (or barycentrics when
 * the mesh has none); spheres the longitude/latitude map, u = 0.5 + atan2(n.x, n.z)/2pi
 * (u = 0.5 faces +z, growing towards +x) and v = 1 - acos(n.y)/pi (1 at the +y pole);
 * planes the coordinates along two unit tangents (plane_tangent); boxes, per face, the
 * fractions along the face's two other axes. Image rows run top to bottom: v = 1 is the
 * first row of the file.
 */
#ifndef CLPT_TEXTURE_H
#define CLPT_TEXTURE_H

#include "surface.h"

/* The unit tangent of a plane's (u, v) frame: the world axis least aligned with n (x,
 * then y, then z on ties), made perpendicular to n. The bitangent is cross(n, t). For
 * the floor (n = +y) this is u = x, v = -z. */
KFN vec3 plane_tangent(vec3 n)
{
    float ax = k_fabs(n.x), ay = k_fabs(n.y), az = k_fabs(n.z);
    vec3 a = (ax <= ay && ax <= az) ? v3(1.0f, 0.0f, 0.0f) : (ay <= az ? v3(0.0f, 1.0f, 0.0f) : v3(0.0f, 0.0f, 1.0f));
    return v3_norm(v3_sub(a, v3_scale(n, v3_dot(n, a))));
}

/* (u, v) of the surface point s (see the top of this file). */
KFN void surface_uv(const SceneView *sc, Surface s, float *u, float *v)
{
    GLOBAL const RenderParams *p = sc->params;
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    uint first_rev = first_box + p->n_boxes, first_plane = first_rev + p->n_revsurfaces;
    if (s.prim < first_tri) {
        vec3 n = s.ng;
        *u = 0.5f + k_atan2(n.x, n.z) * (1.0f / K_TWO_PI);
        *v = 1.0f - k_acos(n.y) * K_INV_PI;
    } else if (s.prim < first_box || (s.prim >= first_rev && s.prim < first_plane)) {
        *u = s.u;     /* triangles: interpolated uv; surfaces of revolution: angle, s */
        *v = s.v;
    } else if (s.prim < first_plane) {
        Box b = sc->boxes[s.prim - first_box];
        vec3 f = v3((s.p.x - b.lo.x) / (b.hi.x - b.lo.x), (s.p.y - b.lo.y) / (b.hi.y - b.lo.y),
                    (s.p.z - b.lo.z) / (b.hi.z - b.lo.z));
        float ax = k_fabs(s.ng.x), ay = k_fabs(s.ng.y);
        *u = ax > 0.5f ? f.z : f.x;
        *v = ay > 0.5f ? f.z : f.y;
    } else {
        vec3 t = plane_tangent(s.ng);
        *u = v3_dot(s.p, t);
        *v = v3_dot(s.p, v3_cross(s.ng, t));
    }
}

/* Row i of the texture's 3x4 matrix applied to (x, y, z, 1). */
KFN float tex_row(Texture tx, int i, vec3 q)
{
    return tx.m[4 * i] * q.x + tx.m[4 * i + 1] * q.y + tx.m[4 * i + 2] * q.z + tx.m[4 * i + 3];
}

KFN vec3 texel_fetch(const SceneView *sc, Texture tx, uint x, uint y)
{
    uint i = y * tx.width + x;
    if (tx.flags & TEX_FLOAT) {
        GLOBAL const uint *t = sc->texels + tx.offset + 3u * i;
        return v3(k_as_float(t[0]), k_as_float(t[1]), k_as_float(t[2]));
    }
    uint c = sc->texels[tx.offset + i];
    vec3 rgb = v3((float)(c & 255u) / 255.0f, (float)((c >> 8) & 255u) / 255.0f,
                  (float)((c >> 16) & 255u) / 255.0f);
    if (tx.flags & TEX_SRGB)
        rgb = v3(k_srgb_to_linear(rgb.x), k_srgb_to_linear(rgb.y), k_srgb_to_linear(rgb.z));
    return rgb;
}

/* Texel index i (any integer, as a float) brought into [0, n) by the wrap mode. */
KFN uint tex_wrap(float i, uint n, uint clamp)
{
    float fn = (float)n;
    if (clamp) return (uint)k_clamp(i, 0.0f, fn - 1.0f);
    float r = i - fn * k_floor(i / fn);
    return r >= fn ? 0u : (uint)r;      /* rounding can give exactly n */
}

/* The four texels around (u, v) and the weights between them (texture_image). */
typedef struct {
    uint xa, xb, ya, yb;
    float fx, fy;
} TexFootprint;

/* Bilinear filtering between the four texel centres around (u, v); texel (i, j) has its
 * centre at u = (i + 0.5)/width, v = 1 - (j + 0.5)/height. */
KFN TexFootprint texture_footprint(Texture tx, float u, float v)
{
    uint clamp = tx.flags & TEX_CLAMP;
    if (!(u == u)) u = 0.0f;
    if (!(v == v)) v = 0.0f;
    /* keep the texel indices small whatever the coordinates (exactly periodic when
     * repeating, a margin beyond the edge when clamping) */
    if (clamp) {
        u = k_clamp(u, -1.0f, 2.0f);
        v = k_clamp(v, -1.0f, 2.0f);
    } else {
        u = u - k_floor(u);
        v = v - k_floor(v);
    }
    float x = u * (float)tx.width - 0.5f, y = (1.0f - v) * (float)tx.height - 0.5f;
    float x0 = k_floor(x), y0 = k_floor(y);
    TexFootprint f;
    f.fx = x - x0;
    f.fy = y - y0;
    f.xa = tex_wrap(x0, tx.width, clamp);
    f.xb = tex_wrap(x0 + 1.0f, tx.width, clamp);
    f.ya = tex_wrap(y0, tx.height, clamp);
    f.yb = tex_wrap(y0 + 1.0f, tx.height, clamp);
    return f;
}

KFN vec3 texture_image(const SceneView *sc, Texture tx, float u, float v)
{
    TexFootprint f = texture_footprint(tx, u, v);
    float fx = f.fx, fy = f.fy;
    vec3 top = v3_add(v3_scale(texel_fetch(sc, tx, f.xa, f.ya), 1.0f - fx), v3_scale(texel_fetch(sc, tx, f.xb, f.ya), fx));
    vec3 bot = v3_add(v3_scale(texel_fetch(sc, tx, f.xa, f.yb), 1.0f - fx), v3_scale(texel_fetch(sc, tx, f.xb, f.yb), fx));
    return v3_add(v3_scale(top, 1.0f - fy), v3_scale(bot, fy));
}

/* An 8-bit texel's alpha (linear, never sRGB-decoded, as glTF and PNG mean it); float
 * textures and images without an alpha channel are opaque (stb_image fills in 255). */
KFN float texel_alpha(const SceneView *sc, Texture tx, uint x, uint y)
{
    if (tx.flags & TEX_FLOAT) return 1.0f;
    return (float)(sc->texels[tx.offset + y * tx.width + x] >> 24) / 255.0f;
}

/* Texture `index`'s alpha at s, filtered as its colour is; checkers are opaque. */
KFN float texture_alpha(const SceneView *sc, uint index, Surface s)
{
    Texture tx = sc->textures[index];
    if (tx.type != TEX_IMAGE) return 1.0f;
    float u, v;
    surface_uv(sc, s, &u, &v);
    vec3 q = v3(u, v, 0.0f);
    TexFootprint f = texture_footprint(tx, tex_row(tx, 0, q), tex_row(tx, 1, q));
    float top = texel_alpha(sc, tx, f.xa, f.ya) * (1.0f - f.fx) + texel_alpha(sc, tx, f.xb, f.ya) * f.fx;
    float bot = texel_alpha(sc, tx, f.xa, f.yb) * (1.0f - f.fx) + texel_alpha(sc, tx, f.xb, f.yb) * f.fx;
    return top * (1.0f - f.fy) + bot * f.fy;
}

/* color0 on cells whose integer coordinates sum to an even number, else color1. */
KFN vec3 texture_checker(Texture tx, vec3 q)
{
    float sum = k_floor(q.x) + k_floor(q.y) + k_floor(q.z);
    float half_sum = sum * 0.5f;
    return half_sum == k_floor(half_sum) ? tx.color0 : tx.color1;
}

/* Texture `index` at surface point s, seen from the side ng_face points to. A solid
 * checker is looked up a hair (1e-4) behind the surface, so a plane lying exactly on a
 * cell boundary (the classic floor at y = 0) takes one cell's colour instead of
 * flickering between two with the rounding of each hit. */
KFN vec3 texture_eval(const SceneView *sc, uint index, Surface s, vec3 ng_face)
{
    Texture tx = sc->textures[index];
    if (tx.type == TEX_CHECKER && (tx.flags & TEX_SOLID)) {
        vec3 q = v3_madd(s.p, ng_face, -1e-4f);
        return texture_checker(tx, v3(tex_row(tx, 0, q), tex_row(tx, 1, q), tex_row(tx, 2, q)));
    }
    float u, v;
    surface_uv(sc, s, &u, &v);
    vec3 q = v3(u, v, 0.0f);
    vec3 t = v3(tex_row(tx, 0, q), tex_row(tx, 1, q), tex_row(tx, 2, q));
    if (tx.type == TEX_CHECKER) return texture_checker(tx, t);
    return texture_image(sc, tx, t.x, t.y);
}

/* The radiance the material emits at s: its emission, times its emission texture
 * (principled) where it has one. */
KFN vec3 material_emission(const SceneView *sc, Material m, Surface s)
{
    if (!KF_HAS(KF_TEXTURES) || m.texture_emission == NO_INDEX) return m.emission;
    return v3_mul(m.emission, texture_eval(sc, m.texture_emission, s, s.ng));
}

/* The material's diffuse colour (albedo) at s: its texture there, or its constant. */
KFN vec3 material_albedo(const SceneView *sc, Material m, Surface s, vec3 ng_face)
{
    return !KF_HAS(KF_TEXTURES) || m.texture == NO_INDEX ? m.albedo : texture_eval(sc, m.texture, s, ng_face);
}

/* dp/du and dp/dv at s, for tangent-space normal maps: a triangle's from its corners
 * and (u, v) (barycentric (u, v) when it has none), a sphere's from its (u, v)
 * parameterisation above. Returns 0 where there is none (boxes, planes) or the mapping
 * is degenerate. */
KFN int surface_tangents(const SceneView *sc, Surface s, vec3 *dpdu, vec3 *dpdv)
{
    GLOBAL const RenderParams *p = sc->params;
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    if (s.prim < first_tri) {
        /* u grows with atan2(x, z) about +y, v with y */
        vec3 n = s.ng;
        *dpdu = v3(n.z, 0.0f, -n.x);
        *dpdv = v3_cross(n, *dpdu);
        return v3_dot(*dpdu, *dpdu) > 0.0f;
    }
    if (s.prim >= first_box) return 0;
    Triangle tr = sc->triangles[s.prim - first_tri];
    float u1 = 1.0f, v1 = 0.0f, u2 = 0.0f, v2 = 1.0f;     /* barycentric: p1 at (1,0), p2 at (0,1) */
    if (tr.shading != NO_INDEX) {
        TriShading sh = sc->shading[tr.shading];
        if (sh.flags & TRI_HAS_UV) {
            u1 = sh.uv1[0] - sh.uv0[0];
            v1 = sh.uv1[1] - sh.uv0[1];
            u2 = sh.uv2[0] - sh.uv0[0];
            v2 = sh.uv2[1] - sh.uv0[1];
        }
    }
    float det = u1 * v2 - u2 * v1;
    if (det == 0.0f) return 0;
    vec3 e1 = v3_sub(tr.p1, tr.p0), e2 = v3_sub(tr.p2, tr.p0);
    float inv = 1.0f / det;
    *dpdu = v3_scale(v3_sub(v3_scale(e1, v2), v3_scale(e2, v1)), inv);
    *dpdv = v3_scale(v3_sub(v3_scale(e2, u1), v3_scale(e1, u2)), inv);
    return 1;
}

/* The shading normal at s after the material's normal map: the texel (r, g, b) read
 * linearly is the tangent-space normal (2r - 1, 2g - 1, 2b - 1), x and y times
 * normal_scale, x along dp/du and y along dp/dv made orthonormal to the shading normal
 * (Gram-Schmidt; y keeps dp/dv's side, so mirrored uv layouts stay right). A result
 * on the far side of the geometric normal, or a surface without tangents, keeps s.ns. */
KFN vec3 material_normal(const SceneView *sc, Material m, Surface s)
{
    vec3 dpdu, dpdv;
    if (!KF_HAS(KF_TEXTURES) || m.type != MAT_PRINCIPLED || m.texture_normal == NO_INDEX ||
        !surface_tangents(sc, s, &dpdu, &dpdv))
        return s.ns;
    vec3 n = s.ns;
    vec3 t = v3_sub(dpdu, v3_scale(n, v3_dot(n, dpdu)));
    float lt = v3_len(t);
    if (!(lt > 0.0f)) return s.ns;
    t = v3_scale(t, 1.0f / lt);
    vec3 b = v3_cross(n, t);
    if (v3_dot(b, dpdv) < 0.0f) b = v3_neg(b);
    vec3 c = texture_eval(sc, m.texture_normal, s, s.ng);
    vec3 tn = v3((2.0f * c.x - 1.0f) * m.normal_scale, (2.0f * c.y - 1.0f) * m.normal_scale, 2.0f * c.z - 1.0f);
    vec3 r = v3_add(v3_add(v3_scale(t, tn.x), v3_scale(b, tn.y)), v3_scale(n, tn.z));
    float lr = v3_len(r);
    if (!(lr > 0.0f)) return s.ns;
    r = v3_scale(r, 1.0f / lr);
    return v3_dot(r, s.ng) > 0.0f ? r : s.ns;
}

/* The material with its textured parameters at s: a principled material's roughness
 * and metallic factors times its metallic-roughness texture's G and B (glTF's packing;
 * the texture is read as declared, so it should be `encoding linear`). */
KFN Material material_at(const SceneView *sc, Material m, Surface s, vec3 ng_face)
{
    if (KF_HAS(KF_TEXTURES) && MAT_IS(m, MAT_PRINCIPLED) && m.texture_rm != NO_INDEX) {
        vec3 t = texture_eval(sc, m.texture_rm, s, ng_face);
        m.roughness *= t.y;
        m.metallic *= t.z;
    }
    return m;
}

#endif /* CLPT_TEXTURE_H */
