/*
 * texture.h — the colour of a texture at a surface point: image textures (bilinear or
 * nearest, sRGB-decoded, repeat, clamp or mirror per axis) and checkerboards (solid, or
 * on the surface's (u, v)).
 *
 * Surface coordinates: triangles use their texture coordinates (or barycentrics when
 * the mesh has none); spheres the longitude/latitude map, u = 0.5 + atan2(n.x, n.z)/2pi
 * (of the object-space normal for an ellipsoid, SphereXform)
 * (u = 0.5 faces +z, growing towards +x) and v = 1 - acos(n.y)/pi (1 at the +y pole);
 * planes the coordinates along two unit tangents (plane_tangent); boxes, per face, the
 * fractions along the face's two other axes. Image rows run top to bottom: v = 1 is the
 * first row of the file.
 */
#ifndef CLPT_TEXTURE_H
#define CLPT_TEXTURE_H

#include "geom/surface.h"
#include "material/srgb_table.h"

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
        if (KF_HAS(KF_SPHERE_XFORM) && sc->spheres[s.prim].xform != 0u) {
            *u = s.u;     /* an ellipsoid: surface_at's, in its object space */
            *v = s.v;
        } else {
            sphere_uv(s.ngo, u, v);
        }
    } else if (s.prim < first_box || (s.prim >= first_rev && s.prim < first_plane)) {
        *u = s.u;     /* triangles: interpolated uv; surfaces of revolution: angle, s */
        *v = s.v;
    } else if (s.prim < first_plane) {
        Box b = sc->boxes[s.prim - first_box];
        /* in the box's own space (an instance's object space) */
        vec3 f = v3((s.po.x - b.lo.x) / (b.hi.x - b.lo.x), (s.po.y - b.lo.y) / (b.hi.y - b.lo.y),
                    (s.po.z - b.lo.z) / (b.hi.z - b.lo.z));
        float ax = k_fabs(s.ngo.x), ay = k_fabs(s.ngo.y);
        *u = ax > 0.5f ? f.z : f.x;
        *v = ay > 0.5f ? f.z : f.y;
    } else {
        vec3 t = plane_tangent(s.ng);
        *u = v3_dot(s.p, t);
        *v = v3_dot(s.p, v3_cross(s.ng, t));
    }
}

/* The (u, v) texture tx is looked up at: the second uv set for TEX_UV1 where the
 * surface has one (glTF's texCoord 1), else surface_uv's. */
KFN void texture_uv(const SceneView *sc, Texture tx, Surface s, float *u, float *v)
{
    if (!(tx.flags & TEX_UV1) || !surface_uv1(sc, s, u, v)) surface_uv(sc, s, u, v);
}

/* Row i of the texture's 3x4 matrix applied to (x, y, z, 1). */
KFN float tex_row(Texture tx, int i, vec3 q)
{
    return tx.m[4 * i] * q.x + tx.m[4 * i + 1] * q.y + tx.m[4 * i + 2] * q.z + tx.m[4 * i + 3];
}

/* An RGBE word's colour (TEX_RGBE): each 8-bit mantissa (red in the low byte) times
 * 2^(e - 136), e the top byte. That is what stb_image makes of a Radiance .hdr pixel
 * (mantissa times ldexp(1, e - 136)), so a packed map keeps every value bit for bit.
 * The packer writes e of at least 10, which keeps the scale 2^(e - 136) a normal float
 * built straight from its exponent bits. */
KFN vec3 rgbe_decode(uint c)
{
    float f = k_as_float(((c >> 24) - 9u) << 23);
    return v3((float)(c & 255u) * f, (float)((c >> 8) & 255u) * f, (float)((c >> 16) & 255u) * f);
}

KFN vec3 texel_fetch(const SceneView *sc, Texture tx, uint x, uint y)
{
    uint i = y * tx.width + x;
    /* a third of the float texels' bytes: the environment map's random lookups miss
     * the caches less (bench/RESULTS.md) */
    if (tx.flags & TEX_RGBE) return rgbe_decode(sc->texels[tx.offset + i]);
    if (tx.flags & TEX_FLOAT) {
        GLOBAL const uint *t = sc->texels + tx.offset + 3u * i;
        return v3(k_as_float(t[0]), k_as_float(t[1]), k_as_float(t[2]));
    }
    uint c = sc->texels[tx.offset + i];
    /* an sRGB code's linear value from the table of k_srgb_to_linear's (the same bits):
     * a pow per channel was 5.6% of a textured glTF scene's time (bench/RESULTS.md) */
    if (tx.flags & TEX_SRGB)
        return v3(srgb_to_linear_table[c & 255u], srgb_to_linear_table[(c >> 8) & 255u],
                  srgb_to_linear_table[(c >> 16) & 255u]);
    return v3((float)(c & 255u) / 255.0f, (float)((c >> 8) & 255u) / 255.0f, (float)((c >> 16) & 255u) / 255.0f);
}

/* How one axis wraps (the TEX_CLAMP_U ... flags of types.h). */
#define TEX_WRAP_REPEAT 0u
#define TEX_WRAP_CLAMP 1u
#define TEX_WRAP_MIRROR 2u

KFN uint tex_wrap_mode(uint flags, uint clamp_bit, uint mirror_bit)
{
    return (flags & clamp_bit) ? TEX_WRAP_CLAMP : ((flags & mirror_bit) ? TEX_WRAP_MIRROR : TEX_WRAP_REPEAT);
}

/* Texel index i (any integer, as a float) brought into [0, n) by the wrap mode: mirror
 * runs 0 .. n-1, n-1 .. 0 and again (each edge texel twice, as GL_MIRRORED_REPEAT). */
KFN uint tex_wrap(float i, uint n, uint mode)
{
    float fn = (float)n;
    if (mode == TEX_WRAP_CLAMP) return (uint)k_clamp(i, 0.0f, fn - 1.0f);
    if (mode == TEX_WRAP_MIRROR) {
        float r = i - 2.0f * fn * k_floor(i / (2.0f * fn));
        if (r >= 2.0f * fn) r = 0.0f;    /* rounding can give exactly 2n */
        return r >= fn ? (uint)(2.0f * fn - 1.0f - r) : (uint)r;
    }
    float r = i - fn * k_floor(i / fn);
    return r >= fn ? 0u : (uint)r;      /* rounding can give exactly n */
}

/* A coordinate made small whatever its size, keeping what it wraps to: exactly
 * periodic when repeating (period 1) or mirroring (period 2), a margin beyond the edge
 * when clamping. NaN becomes 0, and so does an infinity that repeats or mirrors (inf -
 * inf is NaN): the texel index is converted from this to an integer, and a NaN or a
 * value past the integer's range there is undefined behaviour in C and OpenCL alike
 * (a texture map of scale 1e308 read out of bounds under ASan, issue 39). */
KFN float tex_reduce(float u, uint mode)
{
    if (!(u == u)) return 0.0f;
    if (mode == TEX_WRAP_CLAMP) return k_clamp(u, -1.0f, 2.0f);
    float r = mode == TEX_WRAP_MIRROR ? u - 2.0f * k_floor(u * 0.5f) : u - k_floor(u);
    return r == r ? r : 0.0f;
}

/* The four texels around (u, v) and the weights between them (texture_image). */
typedef struct {
    uint xa, xb, ya, yb;
    float fx, fy;
} TexFootprint;

/* Bilinear filtering between the four texel centres around (u, v); texel (i, j) has its
 * centre at u = (i + 0.5)/width, v = 1 - (j + 0.5)/height. TEX_NEAREST: the texel
 * (u, v) lies in, alone (weights 0 and the same texel twice). */
KFN TexFootprint texture_footprint(Texture tx, float u, float v)
{
    uint mu = tex_wrap_mode(tx.flags, TEX_CLAMP_U, TEX_MIRROR_U);
    uint mv = tex_wrap_mode(tx.flags, TEX_CLAMP_V, TEX_MIRROR_V);
    u = tex_reduce(u, mu);
    v = tex_reduce(v, mv);
    TexFootprint f;
    if (tx.flags & TEX_NEAREST) {
        float x = k_floor(u * (float)tx.width), y = k_floor((1.0f - v) * (float)tx.height);
        f.fx = 0.0f;
        f.fy = 0.0f;
        f.xa = f.xb = tex_wrap(x, tx.width, mu);
        f.ya = f.yb = tex_wrap(y, tx.height, mv);
        return f;
    }
    float x = u * (float)tx.width - 0.5f, y = (1.0f - v) * (float)tx.height - 0.5f;
    float x0 = k_floor(x), y0 = k_floor(y);
    f.fx = x - x0;
    f.fy = y - y0;
    f.xa = tex_wrap(x0, tx.width, mu);
    f.xb = tex_wrap(x0 + 1.0f, tx.width, mu);
    f.ya = tex_wrap(y0, tx.height, mv);
    f.yb = tex_wrap(y0 + 1.0f, tx.height, mv);
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
    texture_uv(sc, tx, s, &u, &v);
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
    texture_uv(sc, tx, s, &u, &v);
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

/* The material's diffuse colour (albedo) at s: its texture there, or its constant;
 * times the vertex colour where the surface has one (glTF's COLOR_0). */
KFN vec3 material_albedo(const SceneView *sc, Material m, Surface s, vec3 ng_face)
{
    vec3 a = !KF_HAS(KF_TEXTURES) || m.texture == NO_INDEX ? m.albedo : texture_eval(sc, m.texture, s, ng_face);
    float c[4];
    return surface_color(sc, s, c) ? v3_mul(a, v3(c[0], c[1], c[2])) : a;
}

/* dp/du and dp/dv at s in its object space, for tangent-space normal maps: a triangle's from its corners
 * and (u, v) (barycentric (u, v) when it has none), a sphere's from its (u, v)
 * parameterisation above. Returns 0 where there is none (boxes, planes) or the mapping
 * is degenerate. */
KFN int surface_tangents_local(const SceneView *sc, Surface s, vec3 *dpdu, vec3 *dpdv)
{
    GLOBAL const RenderParams *p = sc->params;
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    if (s.prim < first_tri) {
        /* u grows with atan2(x, z) about +y, v with y */
        vec3 n = s.ngo;
        uint xf = KF_HAS(KF_SPHERE_XFORM) ? sc->spheres[s.prim].xform : 0u;
        if (xf != 0u) {
            /* an ellipsoid: the object space's tangents, carried to the world by M */
            GLOBAL const SphereXform *x = &sc->sphere_xforms[xf - 1u];
            vec3 no = v3_norm(xform_point(x->to_object, s.po));
            vec3 du = v3(no.z, 0.0f, -no.x);
            *dpdu = xform_vector(x->to_world, du);
            *dpdv = xform_vector(x->to_world, v3_cross(no, du));
            return v3_dot(*dpdu, *dpdu) > 0.0f;
        }
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

/* The same in the world: an instance's object-space tangents carried by its M. */
KFN int surface_tangents(const SceneView *sc, Surface s, vec3 *dpdu, vec3 *dpdv)
{
    if (!surface_tangents_local(sc, s, dpdu, dpdv)) return 0;
    *dpdu = surface_vector_to_world(sc, s, *dpdu);
    *dpdv = surface_vector_to_world(sc, s, *dpdv);
    return 1;
}

/* d made orthogonal to the unit n and normalised (Gram-Schmidt) into *t; 0 when d has
 * nothing across n. */
KFN int tangent_along(vec3 n, vec3 d, vec3 *t)
{
    vec3 tt = v3_sub(d, v3_scale(n, v3_dot(n, d)));
    float lt = v3_len(tt);
    if (!(lt > 0.0f)) return 0;
    *t = v3_scale(tt, 1.0f / lt);
    return 1;
}

/* The tangent frame of a normal map at s around the shading normal n: t along the
 * surface's given tangent (glTF's TANGENT) where it has a usable one, with the
 * bitangent cross(n, t) times the tangent's w sign (glTF 2.0, 3.7.2.1); else t along
 * dp/du, with the bitangent on dp/dv's side (so mirrored uv layouts stay right).
 * 0 when there is no usable frame. */
KFN int normal_map_frame(const SceneView *sc, Surface s, vec3 n, vec3 *t, vec3 *b)
{
    vec3 given, dpdu, dpdv;
    float sign = 1.0f;
    if (surface_tangent(sc, s, &given, &sign) && tangent_along(n, given, t)) {
        *b = v3_cross(n, *t);
        if (sign < 0.0f) *b = v3_neg(*b);
        return 1;
    }
    if (!surface_tangents(sc, s, &dpdu, &dpdv) || !tangent_along(n, dpdu, t)) return 0;
    *b = v3_cross(n, *t);
    if (v3_dot(*b, dpdv) < 0.0f) *b = v3_neg(*b);
    return 1;
}

/* The shading normal at s after the material's normal map: the texel (r, g, b) read
 * linearly is the tangent-space normal (2r - 1, 2g - 1, 2b - 1), x and y times
 * normal_scale, x along the frame's tangent and y along its bitangent
 * (normal_map_frame). A result on the far side of the geometric normal, or a surface
 * without a frame, keeps s.ns. */
KFN vec3 material_normal(const SceneView *sc, Material m, Surface s)
{
    vec3 t, b;
    vec3 n = s.ns;
    if (!KF_HAS(KF_TEXTURES) || m.type != MAT_PRINCIPLED || m.texture_normal == NO_INDEX ||
        !normal_map_frame(sc, s, n, &t, &b))
        return s.ns;
    vec3 c = texture_eval(sc, m.texture_normal, s, s.ng);
    vec3 tn = v3((2.0f * c.x - 1.0f) * m.normal_scale, (2.0f * c.y - 1.0f) * m.normal_scale, 2.0f * c.z - 1.0f);
    vec3 r = v3_add(v3_add(v3_scale(t, tn.x), v3_scale(b, tn.y)), v3_scale(n, tn.z));
    float lr = v3_len(r);
    if (!(lr > 0.0f)) return s.ns;
    r = v3_scale(r, 1.0f / lr);
    return v3_dot(r, s.ng) > 0.0f ? r : s.ns;
}

/* Sets *m's textured parameters to their values at s: a principled material's
 * roughness and metallic factors times its metallic-roughness texture's G and B
 * (glTF's packing; the texture is read as declared, so it should be `encoding linear`),
 * and its specular, sheen and diffuse-transmission factors times theirs.
 * In place, as material_resolve (mix.h). */
KFN void material_at(const SceneView *sc, Material *m, Surface s, vec3 ng_face)
{
    if (!KF_HAS(KF_TEXTURES) || m->type != MAT_PRINCIPLED) return;
    if (m->texture_rm != NO_INDEX) {
        vec3 t = texture_eval(sc, m->texture_rm, s, ng_face);
        m->roughness *= t.y;
        m->metallic *= t.z;
    }
    /* KHR_materials_specular and _sheen: factor times texture, the strengths in alpha */
    if (m->texture_specular != NO_INDEX) m->specular_factor *= texture_alpha(sc, m->texture_specular, s);
    if (m->texture_specular_color != NO_INDEX)
        m->specular_color = v3_mul(m->specular_color, texture_eval(sc, m->texture_specular_color, s, ng_face));
    if (m->texture_sheen_color != NO_INDEX)
        m->sheen_color = v3_mul(m->sheen_color, texture_eval(sc, m->texture_sheen_color, s, ng_face));
    if (m->texture_sheen_roughness != NO_INDEX)
        m->sheen_roughness *= texture_alpha(sc, m->texture_sheen_roughness, s);
    /* KHR_materials_diffuse_transmission: the same, the factor in alpha */
    if (m->texture_diffuse_transmission != NO_INDEX)
        m->diffuse_transmission *= texture_alpha(sc, m->texture_diffuse_transmission, s);
    if (m->texture_diffuse_transmission_color != NO_INDEX)
        m->diffuse_transmission_color =
            v3_mul(m->diffuse_transmission_color, texture_eval(sc, m->texture_diffuse_transmission_color, s, ng_face));
}

#endif /* CLPT_TEXTURE_H */
