/*
 * types.h — every struct that crosses the host/device boundary, defined once.
 *
 * Included by the OpenCL kernels and by the host C code, so the layout has exactly one
 * definition. Only 4-byte scalars appear in these structs (float, uint, int) and vec3 is
 * a plain struct of three floats: OpenCL's float3 is 16 bytes but 12 in C, and bool,
 * size_t and pointers differ between the two worlds. Every struct's size is a multiple
 * of 16 bytes, with explicit padding, noted beside it; the host build checks the sizes
 * and offsets with _Static_assert, and tests/test_kernels.c asks each OpenCL device for
 * the same numbers (kernel k_layout in entry.cl).
 */
#ifndef CLPT_TYPES_H
#define CLPT_TYPES_H

#include "util/compat.h"

/* Sentinel for "no index" in any uint field (no light, no shading record, a miss). */
#define NO_INDEX 0xffffffffu

/* Longest kd-tree descent the traversal stack can hold; the builder never exceeds it. */
#define KD_MAX_DEPTH 64

/* Fixed-point scale of the film: radiance is accumulated as 64-bit integers in units of
 * 2^-FILM_FRAC_BITS, so that adding batches in any grouping gives the same bits. */
#define FILM_FRAC_BITS 24
/* A single sample's contribution is clamped to this radiance (and NaN/inf dropped), which
 * keeps 2^31 samples of a pixel far from int64 overflow. */
#define FILM_MAX_SAMPLE 65536.0f

/* Kernel features: what one OpenCL program is compiled with (-D CLPT_FEATURES=<bits>,
 * host/device/device_ocl.c derives them from the scene). Code for a feature the scene
 * does not use is compiled out, which cuts the driver's compile time (LLVM's) by about
 * half for a scene of diffuse materials; the bits are part of the kernel cache key.
 * Each switch only removes code that the scene cannot reach, so images stay the same
 * bit for bit. Without CLPT_FEATURES (the scalar C device, the tests' own builds)
 * everything is compiled. */
#define KF_PATH 0x1u            /* the path tracer as a wavefront (k_raygen ... k_shadow, k_film) */
#define KF_WHITTED 0x2u         /* the classic ray tracer and the AOVs (k_whitted, k_film) */
#define KF_TEXTURES 0x4u        /* a material reads a texture */
#define KF_ALPHA 0x8u           /* a material is cut out (MAT_ALPHA_MASK or _BLEND) */
#define KF_ENV_MAP 0x10u        /* background BG_MAP, with its light LIGHT_ENV */
#define KF_CUBEMAP 0x20u        /* background BG_CUBEMAP */
#define KF_REVSURFACE 0x40u     /* surfaces of revolution */
#define KF_SPHERES 0x80u
#define KF_BOXES 0x100u
#define KF_PLANES 0x200u
#define KF_DELTA_LIGHTS 0x400u  /* point, spot or directional lights */
/* 0x800u ... 0x20000u and 0x800000u: material types, each its own switch, named
 * KF_MAT_DIFFUSE ... (MATERIAL_TYPES below; KF_MATERIAL(MAT_DIFFUSE) is the same) */
#define KF_PATH_MEGAKERNEL 0x80000u     /* the path tracer as one kernel (k_path, k_film) */
#define KF_KDTREE 0x100000u     /* the scene's tree is the kd-tree (kernels/accel/traverse.h) */
#define KF_BVH 0x200000u        /* ... the 8-wide BVH (kernels/accel/traverse_bvh.h) */
#define KF_PATH_LANES 0x400000u /* the megakernel eight paths at a time (k_path_lanes, k_film;
                                 * kernels/integrator/shade_lanes.h): CPUs, scenes it shades fast */
#define KF_SPHERE_XFORM 0x1000000u /* a sphere under a transform (an ellipsoid, SphereXform) */
#define KF_MEDIA 0x2000000u     /* participating media or their boundaries (kernels/medium/,
                                 * RenderParams.has_media; docs/media.md) */
#define KF_INSTANCES 0x10000000u /* instances of objects: the BVH's two levels (Instance) */
#define KF_MOTION 0x40000000u   /* motion blur: a moving camera or moving instances
                                 * (Camera.moving, MotionKey; docs/motion.md) */
/* every bit above and every material type's */
#define KF_ALL (KF_PATH | KF_WHITTED | KF_TEXTURES | KF_ALPHA | KF_ENV_MAP | KF_CUBEMAP | KF_REVSURFACE | \
                KF_SPHERES | KF_BOXES | KF_PLANES | KF_DELTA_LIGHTS | KF_PATH_MEGAKERNEL | KF_KDTREE | KF_BVH | \
                KF_PATH_LANES | KF_SPHERE_XFORM | KF_MEDIA | KF_INSTANCES | KF_MOTION MATERIAL_TYPES(KF_MATERIAL_OR_))
#define KF_MATERIAL_OR_(name, value, bit, traits, lobes) | (bit)
#ifndef CLPT_FEATURES
#define CLPT_FEATURES 0xffffffffu   /* every switch (KF_ALL, which is not usable here: a
                                     * macro of the material list) */
#endif
/* Paths per work-item of k_path_lanes (KF_PATH_LANES): one float8 of each quantity. */
#define PATH_LANES 8u
/* Whether feature f is compiled in: a constant, so the compiler drops what is not. */
#define KF_HAS(f) ((CLPT_FEATURES & (f)) != 0u)

/* ---------------------------------------------------------------- material types
 * Every material type, one line each, X(name, value, feature bit, traits, lobes):
 *   name, value  its enum MaterialType constant, stored in Material.type
 *   feature bit  the KF_ switch that compiles its code in (a free bit of the list
 *                above); 0: always compiled (the mix, which kernels/material/mix.h resolves
 *                before anything asks what it scatters)
 *   traits       MT_* below: what the integrators ask of a type as a whole
 *   lobes        the stem of its scattering functions, <lobes>_bsdf_has_density,
 *                _bsdf_eval and _bsdf_sample, which kernels/bsdf/bsdf.h dispatches to; they
 *                live in the header of its lobe family (docs/design.md, "Materials")
 * The enum, the KF_MAT_* switches, KF_ALL, the trait predicates, the dispatch and the
 * host's feature scan (host/device/kernel_features.c) are generated from it.
 *
 * Every type may also emit `emission`; a non-zero emission makes the primitives with
 * that material lights. Emission leaves the front side only (the side the outward normal
 * of a sphere or box, or the winding normal (p1-p0)x(p2-p0) of a triangle, points to),
 * unless the material has MAT_TWO_SIDED.
 *   MAT_DIFFUSE     Lambertian, albedo
 *   MAT_METAL       mirror reflection perturbed by fuzz, tinted by albedo
 *   MAT_DIELECTRIC  glass, Fresnel reflection/refraction, ior; GGX roughness and
 *                   anisotropy (Walter et al. 2007) and MAT_THIN
 *   MAT_EMISSIVE    emits `emission`, reflects nothing
 *   MAT_PHONG       albedo = diffuse colour, specular, shininess, plus mirror
 *                   (`reflective`) and Fresnel-weighted see-through (`transparent`,
 *                   ior) parts: the classic ray tracer's material (docs/classic-format.md)
 *   MAT_CONDUCTOR   GGX metal (kernels/bsdf/conductor.h): complex index eta + i k, or Schlick
 *                   from F0 = specular (MAT_F0); tinted by albedo; roughness,
 *                   anisotropy; smooth: a Fresnel mirror
 *   MAT_PRINCIPLED  glTF metallic-roughness (kernels/bsdf/principled.h): base colour =
 *                   albedo, metallic, roughness, transmission + ior (MAT_THIN),
 *                   clearcoat + clearcoat_roughness, specular_factor + specular_color,
 *                   sheen_color + sheen_roughness, diffuse_transmission (+ _color),
 *                   and inside a solid (not MAT_THIN)
 *                   Beer-Lambert absorption
 *   MAT_MIX         pbrt's mix (kernels/material/mix.h): at each hit either material mix_a or,
 *                   with probability amount, mix_b scatters; its own emission and
 *                   MAT_TWO_SIDED are what the surface emits
 *   MAT_LAYERED     pbrt-v4's coated materials (kernels/bsdf/layered.h): a dielectric
 *                   interface (ior, roughness, anisotropy) over a base (layer_base:
 *                   Lambertian albedo, or a conductor eta + i k with base_roughness,
 *                   base_anisotropy), a medium between (layer_*)
 */
#define MATERIAL_TYPES(X) \
    X(MAT_DIFFUSE,    0, 0x800u,    MT_SCATTERS | MT_KEEPS_NORMAL,                 diffuse)    \
    X(MAT_METAL,      1, 0x1000u,   MT_SCATTERS,                                   metal)      \
    X(MAT_DIELECTRIC, 2, 0x2000u,   MT_SCATTERS | MT_TRANSMITS,                    dielectric) \
    X(MAT_EMISSIVE,   3, 0x4000u,   0u,                                            none)       \
    X(MAT_PHONG,      4, 0x8000u,   MT_SCATTERS | MT_KEEPS_NORMAL,                 phong)      \
    X(MAT_CONDUCTOR,  5, 0x10000u,  MT_SCATTERS,                                   conductor)  \
    X(MAT_PRINCIPLED, 6, 0x20000u,  MT_SCATTERS | MT_TRANSMITS | MT_ABSORBS,       principled) \
    X(MAT_MIX,        7, 0u,        0u,                                            none)       \
    X(MAT_LAYERED,    8, 0x800000u, MT_SCATTERS,                                   layered)

/* Traits: what a material type may do, whatever its parameters. */
#define MT_SCATTERS 1u      /* reflects or transmits light (the integrators stop at a
                             * surface of a type without it) */
#define MT_TRANSMITS 2u     /* a lobe with a density passes light through the surface:
                             * next-event estimation also samples lights below it */
#define MT_ABSORBS 4u       /* a solid of it (not MAT_THIN) absorbs along the paths
                             * inside (Material.absorption, Beer-Lambert) */
#define MT_KEEPS_NORMAL 8u  /* its lobes take the shading normal as it is, even facing
                             * away from the viewer (bsdf_normal) */

#define MAT_ENUM_(name, value, bit, traits, lobes) name = value,
enum MaterialType { MATERIAL_TYPES(MAT_ENUM_) };
#undef MAT_ENUM_
#define KF_MAT_ENUM_(name, value, bit, traits, lobes) KF_##name = bit,
enum MaterialFeature { MATERIAL_TYPES(KF_MAT_ENUM_) };
#undef KF_MAT_ENUM_
/* The feature bit of material type `name` (an enum MaterialType constant's name). */
#define KF_MATERIAL(name) KF_##name
/* Whether the code of the material type with feature bit `bit` is compiled in. */
#define KF_HAS_MATERIAL(bit) ((bit) == 0u || KF_HAS(bit))
/* m.type == t (a constant's name), known false at compile time when no material of
 * type t is compiled in. */
#define MAT_IS(m, t) (KF_HAS_MATERIAL(KF_##t) && (m).type == (t))

/* Whether material type `type` has trait `trait` (MT_*): a constant that the compiler
 * folds, false when no type compiled in has it. */
KFN int material_has(uint type, uint trait)
{
#define MAT_HAS_(name, value, bit, traits, lobes) \
    if (((traits) & trait) != 0u && KF_HAS_MATERIAL(bit) && type == (value)) return 1;
    MATERIAL_TYPES(MAT_HAS_)
#undef MAT_HAS_
    return 0;
}
KFN int material_scatters(uint type) { return material_has(type, MT_SCATTERS); }
KFN int material_transmits(uint type) { return material_has(type, MT_TRANSMITS); }
KFN int material_absorbs(uint type) { return material_has(type, MT_ABSORBS); }

/* The feature bit of material type `type`; KF_ALL for a value that is none. */
KFN uint material_feature(uint type)
{
#define MAT_FEATURE_(name, value, bit, traits, lobes) if (type == (value)) return bit;
    MATERIAL_TYPES(MAT_FEATURE_)
#undef MAT_FEATURE_
    return KF_ALL;
}

typedef struct { float x, y, z; } vec3;                 /* 12 bytes, align 4 */

typedef struct {                                        /* 32 bytes */
    vec3 o;  float tmin;
    vec3 d;  float tmax;
} Ray;

typedef struct {                                        /* 32 bytes */
    float t;        /* distance along the (unnormalised) ray direction */
    uint prim;      /* global primitive id (see RenderParams), NO_INDEX for a miss */
    float u, v;     /* triangles: barycentrics of p1 and p2; boxes: u = face index */
    uint inst;      /* the instance whose prototype holds prim (Instance, below), or
                     * NO_INDEX for the world's own primitives (docs/instancing.md) */
    float flight_stop;   /* flight_drawn 1: the distance at which the flight through
                          * the path's medium stops, drawn before the walk that found
                          * this hit (trace_flight, kernels/medium/medium_path.h) */
    uint flight_drawn;   /* 1 as above; 0 from every other walk */
    uint pad2;
} Hit;

/* kd-tree node, 8 bytes (layout in docs/kdtree.md).
 * Interior: bits = axis (0,1,2) in the low 2 bits | KD_EMPTY_BELOW, KD_EMPTY_ABOVE when
 *           that child is an empty leaf | index of the "above" child << 4; the "below"
 *           child is the next node; data = the plane position (float bits).
 * Leaf:     bits = 3 | KD_LEAF_OTHERS if it holds spheres or boxes | triangle groups << 3;
 *           data = the offset of its record in the leaf data array (the leaf_prims
 *           buffer, 32-bit words): that many triangle groups of KD_GROUP_WORDS words
 *           each, then, with KD_LEAF_OTHERS, a count and the global ids of the
 *           spheres and boxes. A group holds KD_GROUP triangles: their global ids, then
 *           the corners as 9 rows of KD_GROUP floats (p0.x, p0.y, p0.z, p1.x, ... p2.z),
 *           the last triangle repeated in the unused lanes. */
typedef struct {
    uint data;      /* interior: as_uint(split position); leaf: offset in the leaf data */
    uint bits;
} KdNode;

#define KD_LEAF 3u
#define KD_EMPTY_BELOW 4u
#define KD_EMPTY_ABOVE 8u
#define KD_LEAF_OTHERS 4u
#define KD_GROUP 8u
#define KD_GROUP_WORDS (KD_GROUP * 10u)

/* A node of the 8-wide BVH (host/accel/bvh.c, walked by kernels/accel/traverse_bvh.h):
 * the boxes of up to BVH_WIDTH children as six rows of 8 lanes (lo x, hi x, lo y, hi y,
 * lo z, hi z: the layout one float8 load per row wants), and per child a reference and
 * its kind: BVH_CHILD_NONE for an unused lane (its box is empty: lo +inf, hi -inf),
 * BVH_CHILD_NODE with ref the child's node index, or a leaf's KdNode bits (KD_LEAF,
 * which is never 0 or 1) with ref the offset of its record in the leaf data, which
 * has the kd-tree's leaf layout (above). A node's children are in lanes 0 .. n-1, its
 * unused lanes after them (the packet walk stops at the first). Node 0 is the root. */
#define BVH_WIDTH 8u
/* Entries of the walk's stack: the build keeps every path's sum of (children - 1), what
 * a walk leaves on the stack above a node, within it (host/accel/bvh.c). */
#define BVH_STACK 128u
#define BVH_CHILD_NONE 0u
#define BVH_CHILD_NODE 1u
/* A top-level child that is one instance (ref: its index in the instances buffer): the
 * walk carries the ray into the instance's object space and goes on at its prototype's
 * root (Instance.root). Only a scene with instances has them (docs/instancing.md). */
#define BVH_CHILD_INSTANCE 2u
typedef struct {                                        /* 256 bytes */
    float box[6][BVH_WIDTH];
    uint ref[BVH_WIDTH];
    uint kind[BVH_WIDTH];
} BvhNode;

/* A node of the top level over instances, compressed (after Ylitie, Karras and Laine
 * 2017, "Efficient incoherent ray traversal on GPUs through compressed wide BVHs", and
 * Embree's compressed BVH nodes): a child's box planes are 8-bit steps q, one step
 * 2^(e - 150) per axis, its e in meta. A plane decodes as
 *     as_float(e << 23 | q) + offset[axis]
 * the float of exponent e whose mantissa is q, which is 2^(e - 127) + q * step exactly
 * (q < 2^8 stays in the mantissa's low bits), plus the axis's offset: an integer or,
 * no conversion and no multiply, and one correctly rounded add on every device. The
 * host (host/accel/bvh_top.c) checks each plane against the child's float box with that
 * very expression: lower planes rounded down, upper planes up, every child box holds
 * its instance. The walk then enters at least the boxes the float nodes gave it and
 * finds the same closest hit by the tie rule (docs/instancing.md). The children are in
 * lanes 0 .. n-1 (n in meta's top byte; other lanes are never entered); ref is a
 * top-level node index, or an instance index with BVH_TOP_INSTANCE set. The prototypes
 * below stay BvhNode: they hold the triangles, where a wider box would cost leaf tests,
 * and the memory is per instance. */
#define BVH_TOP_INSTANCE 0x80000000u
typedef struct {                                        /* 96 bytes */
    float offset[3];        /* per axis: the decoded plane of q = 0 is 2^(e - 127) + offset */
    uint meta;              /* bits 0-7, 8-15, 16-23: e of x, y, z; bits 24-31: n */
    uint q[6][2];           /* rows lo x, hi x, lo y, hi y, lo z, hi z; lane l is byte
                             * l % 4 (the low byte first) of word l / 4 */
    uint ref[BVH_WIDTH];
} BvhTopNode;

/* An instance of an object (a prototype: primitives in the scene's arrays that no tree
 * but their own holds) under an affine transform M, docs/instancing.md. Rays enter the
 * prototype's BVH in its object space: origin and direction both mapped by M^-1, the
 * direction not renormalised, so a hit's t is the world ray's. Both matrices are 3x4
 * row-major, as SphereXform's; the normal matrix is the transpose of to_object's linear
 * part. */
#define INST_IDENTITY 1u   /* M is the identity: rays and surfaces are not transformed */
#define INST_MIRROR 2u     /* det M < 0 (the host's: normals by M^-T keep their sides) */
#define INST_WORLD 4u      /* the world's own primitives under the top level: hits carry
                            * inst NO_INDEX, as in a scene without instances */
#define INST_MOTION 8u     /* M moves over the shutter (KF_MOTION, docs/motion.md): its keys
                            * start at motion_keys[instance_motion[i]], and M and M^-1
                            * are those at the path's time (geom/instance.h); to_world and
                            * to_object hold its first key's pose, for the host */
typedef struct {                                        /* 108 bytes */
    float to_world[12];       /* M: object -> world */
    float to_object[12];      /* M^-1: world -> object */
    uint root;                /* the BVH node of its prototype's root; under --accel
                               * kdtree its prototype's KdProto (kd_protos) */
    uint material;            /* the material that replaces every primitive's, or NO_INDEX */
    uint flags;               /* INST_* */
    /* the prototype's index is the host's alone (stats, flattening, lights): it lives
     * in Scene.instance_objects, not in what every device holds per instance */
} Instance;

/* A prototype's kd-tree under --accel kdtree in a scene with instances (host/accel/
 * kd_inst.c, docs/instancing.md): the top level stays the compressed BVH over instances
 * and each prototype's kd-tree lies in the shared kd node and leaf arrays (nodes,
 * leaf_prims), its interior nodes' "above" indices and its leaves' record offsets
 * already moved to where it lies. Instance.root is then the prototype's index in the
 * kd_protos buffer; the walk clips the object-space ray to lo, hi as a one-level kd
 * walk clips it to RenderParams.bounds_lo, hi. */
typedef struct {                                        /* 32 bytes */
    vec3 lo;   uint root;     /* the box of the tree's root; its root node in nodes[] */
    vec3 hi;   uint pad0;
} KdProto;

/* Global primitive ids: [0, n_spheres) spheres, then triangles, then boxes, then
 * surfaces of revolution, then planes. All but the infinite planes are in the kd-tree. */
typedef struct {                                        /* 32 bytes */
    vec3 center;  float radius;
    uint material;
    uint light;     /* index into lights[] if emissive, else NO_INDEX; in an object,
                     * its index among the object's emitters (LIGHT_INSTANCED) */
    uint xform;     /* 0: a plain sphere (centre, radius); else 1 + its index in the
                     * sphere_xforms buffer: the unit sphere under that transform, an
                     * ellipsoid, whose centre and radius are then only a bounding
                     * sphere. 0 rather than NO_INDEX for "none" so that every sphere
                     * made before transforms existed, its padding zeroed, stays plain. */
    uint pad1;
} Sphere;

/* A sphere under an affine transform M (pbrt's sphere under a non-uniform scale): the
 * unit sphere at the origin of object space, carried to the world by M. Rays are
 * intersected in object space (PBR 4th ed., 6.2: pbrt-v4's Sphere works there too),
 * which keeps t, since the direction is mapped without being renormalised. Both
 * matrices are 3x4 row-major, (x, y, z, 1) -> row . (x, y, z, 1); the normal matrix is
 * the transpose of to_object's linear part, so it is not stored. */
typedef struct {                                        /* 96 bytes */
    float to_world[12];       /* M: object -> world */
    float to_object[12];      /* M^-1: world -> object */
} SphereXform;

typedef struct {                                        /* 48 bytes */
    vec3 p0;  uint material;
    vec3 p1;  uint light;
    vec3 p2;  uint shading;   /* index into TriShading[] or NO_INDEX (flat, no uv) */
} Triangle;

typedef struct {                                        /* 64 bytes */
    vec3 n0, n1, n2;          /* per-vertex shading normals (unit) */
    float uv0[2], uv1[2], uv2[2];
    uint flags;               /* TRI_HAS_NORMALS | TRI_HAS_UV | TRI_HAS_EXTRA */
} TriShading;
#define TRI_HAS_NORMALS 1u
#define TRI_HAS_UV 2u
#define TRI_HAS_EXTRA 4u      /* tri_extra_of[this record's index] names its TriExtra */

/* The corner attributes that only some glTF meshes carry: given tangents (TANGENT), a
 * second uv set (TEXCOORD_1) and vertex colours (COLOR_0). They live in a side array
 * instead of TriShading so that the records every smooth or textured triangle reads
 * stay 64 bytes: a triangle with any of them has a shading record with TRI_HAS_EXTRA,
 * and the scene's tri_extra_of buffer (one uint per shading record, NO_INDEX for none;
 * empty when no triangle has extras) points into the TriExtra array. Only the shading
 * of a surface that has extras ever reads either buffer (docs/gltf.md). */
typedef struct {                                        /* 128 bytes */
    float tangent[3][4];      /* per corner: unit tangent (world xyz), w = bitangent sign */
    float color[3][4];        /* per corner: linear RGBA multiplying base colour and alpha */
    float uv[3][2];           /* per corner: the second uv set (v up, as TriShading's) */
    uint flags;               /* EXTRA_TANGENT | EXTRA_COLOR | EXTRA_UV1 */
    uint pad0;
} TriExtra;
#define EXTRA_TANGENT 1u
#define EXTRA_COLOR 2u
#define EXTRA_UV1 4u

typedef struct {                                        /* 32 bytes */
    vec3 lo;  uint material;
    vec3 hi;  uint light;
} Box;

/* A surface of revolution (kernels/geom/revsurface.h): a profile curve (x(s), y(s)) in the
 * xy plane revolved about the vertical axis x = axis_x, z = axis_z. The profile is
 * n_segments Bezier segments of `degree`, stored as (x, y) float pairs in rev_points
 * from pair `first` on; consecutive segments share their end point, so the surface
 * holds n_segments * degree + 1 pairs. lo..hi bound it (the kd-tree box). Surfaces of
 * revolution never emit light (the classic format they come from has no emission). */
#define REV_MAX_DEGREE 24u     /* longest Bezier profile: 25 control points */
typedef struct {                                        /* 48 bytes */
    vec3 lo;  uint material;
    vec3 hi;  uint first;
    float axis_x, axis_z;
    uint n_segments, degree;
} RevSurface;

typedef struct {                                        /* 32 bytes */
    vec3 normal;  float offset;  /* the points p with dot(normal, p) == offset */
    uint material;
    uint pad0, pad1, pad2;
} Plane;

/* MAT_LAYERED's bases */
#define LAYER_BASE_DIFFUSE 0u
#define LAYER_BASE_CONDUCTOR 1u

typedef struct {                                        /* 320 bytes */
    uint type;                /* enum MaterialType */
    uint texture;             /* albedo texture index, NO_INDEX when none */
    float ior;
    float fuzz;
    vec3 albedo;    float shininess;
    vec3 emission;  uint flags;   /* MAT_* flags */
    vec3 specular;  float roughness;   /* perceptual: GGX alpha = roughness^2 */
    vec3 reflective;  float anisotropy; /* MAT_PHONG: perfect mirror part */
    vec3 transparent; float metallic;      /* MAT_PHONG: refracted part (split by Fresnel) */
    vec3 eta;         float transmission;  /* MAT_CONDUCTOR: complex index of refraction ... */
    vec3 k;           float clearcoat;     /* ... eta + i k per RGB channel */
    float clearcoat_roughness;             /* MAT_PRINCIPLED, as roughness */
    uint texture_rm;                       /* MAT_PRINCIPLED: glTF metallic-roughness
                                            * texture (G roughness, B metallic), or
                                            * NO_INDEX */
    uint texture_normal;                   /* MAT_PRINCIPLED: tangent-space normal map
                                            * (OpenGL/glTF: green = +v), or NO_INDEX */
    float normal_scale;                    /* scales the map's x and y (glTF's scale) */
    float alpha;                           /* MAT_PRINCIPLED: opacity (glTF baseColor
                                            * alpha), times the base-colour texture's
                                            * alpha; read under MAT_ALPHA_MASK/BLEND */
    float alpha_cutoff;                    /* MAT_ALPHA_MASK: opaque where alpha >= this */
    uint texture_emission;                 /* MAT_PRINCIPLED: multiplies emission, or
                                            * NO_INDEX */
    float subsurface;                      /* MAT_PRINCIPLED, solid: the share of the diffuse
                                            * lobe that refracts into the interior instead
                                            * and walks its medium (medium_in, a MEDIUM_WALK
                                            * medium: docs/subsurface.md); 0: none */
    uint mix_a, mix_b;                     /* MAT_MIX: the two materials' indices */
    float mix_amount;                      /* MAT_MIX: mix_b's probability, times ... */
    uint mix_texture;                      /* ... this texture's red channel, or NO_INDEX */
    vec3 absorption;                       /* MAT_PRINCIPLED, solid: sigma_a per unit of
                                            * scene length inside the material (0: clear;
                                            * KHR_materials_volume's attenuation) */
    float specular_factor;                 /* MAT_PRINCIPLED: scales the dielectric F0 and
                                            * F90 (KHR_materials_specular; 1 by default) */
    vec3 specular_color;                   /* ... scales F0 per channel (1 1 1 by default) */
    float sheen_roughness;                 /* MAT_PRINCIPLED: perceptual, alpha = its square */
    vec3 sheen_color;                      /* ... the sheen layer's colour (0: no sheen) */
    uint texture_specular;                 /* alpha times specular_factor, or NO_INDEX */
    uint texture_specular_color;           /* RGB times specular_color, or NO_INDEX */
    uint texture_sheen_color;              /* RGB times sheen_color, or NO_INDEX */
    uint texture_sheen_roughness;          /* alpha times sheen_roughness, or NO_INDEX */
    float diffuse_transmission;            /* MAT_PRINCIPLED: the diffuse layer's share that
                                            * passes to the back side, Lambertian
                                            * (KHR_materials_diffuse_transmission); 0: none */
    vec3 layer_albedo;                     /* MAT_LAYERED: the medium's scattering albedo */
    float layer_thickness;                 /* ... its optical depth (extinction 1) */
    float layer_g;                         /* ... Henyey-Greenstein asymmetry */
    uint layer_depth;                      /* ... most scatterings of a walk (maxdepth) */
    uint layer_samples;                    /* ... walks per evaluation (nsamples) */
    uint layer_base;                       /* LAYER_BASE_*: albedo, or eta, k and ... */
    float base_roughness, base_anisotropy; /* ... the conductor's GGX */
    uint medium_in, medium_out;            /* the media this surface bounds (pbrt's
                                            * MediumInterface; kernels/medium/medium.h):
                                            * inside (behind the geometric normal) and
                                            * outside, each 0 for vacuum or 1 + an index
                                            * into media[]; equal: no boundary, a ray
                                            * keeps its medium */
    vec3 diffuse_transmission_color;       /* MAT_PRINCIPLED: tints the diffuse
                                            * transmission (1 1 1 by default) */
    uint texture_diffuse_transmission;     /* alpha times diffuse_transmission, or NO_INDEX */
    uint texture_diffuse_transmission_color;  /* RGB times diffuse_transmission_color, or
                                               * NO_INDEX */
    uint pad_dt0, pad_dt1, pad_dt2;
} Material;

#define MIX_MAX_DEPTH 8u        /* MAT_MIX: mixes nested at most this deep (mix.h) */

#define MAT_TWO_SIDED 1u        /* emits from both sides of its surface */
#define MAT_F0 2u               /* conductor: Schlick's Fresnel from F0 = specular */
#define MAT_THIN 4u             /* dielectric: a thin sheet, no bend on refraction */
#define MAT_ALPHA_MASK 8u       /* glTF alphaMode MASK: cut out where alpha < alpha_cutoff */
#define MAT_ALPHA_BLEND 16u     /* glTF alphaMode BLEND: a hit is kept with probability
                                 * alpha (kernels/accel/alpha.h) */
/* either: the material may be cut out somewhere (the alpha check, the kernels' KF_ALPHA,
 * RenderParams.has_alpha and light sampling all ask this) */
#define MAT_ALPHA_ANY (MAT_ALPHA_MASK | MAT_ALPHA_BLEND)
#define MAT_INTERFACE 32u       /* no surface at all, only a boundary between media
                                 * (`material none`, pbrt's "interface"): rays pass
                                 * straight through it, changing medium (KF_MEDIA) */

/* Every light type, listed once: X(name, value, feature bit, traits, keyword), as
 * MATERIAL_TYPES. The enum, the kernel feature a scene's lights need
 * (kernel_features.c) and the trait predicates come from it; a new type is a line here,
 * its sampling in kernels/light/lights.h and its keys in the readers.
 *   LIGHT_AREA         the emissive primitives (an emissive material's surfaces)
 *   LIGHT_POINT        a point radiating `intensity` (W/sr) evenly
 *   LIGHT_DIRECTIONAL  parallel light from infinitely far (irradiance, W/m^2)
 *   LIGHT_SPOT         a point light within a cone (cos_inner, cos_outer, spot_falloff)
 *   LIGHT_ENV          the environment map's light (kernels/light/envmap.h)
 *   LIGHT_INSTANCED    an emissive triangle of an object as one instance places it
 *                      (docs/instancing.md): an area light whose geometry the record
 *                      holds in the world (below), compiled in with the instances
 *   LIGHT_MOVING       the same for an instance that moves (INST_MOTION, docs/motion.md):
 *                      the record holds the object-space geometry and the instance,
 *                      placed at the path's time when sampled (below); compiled in
 *                      with motion (a scene with moving instances has KF_INSTANCES too) */
#define LIGHT_TYPES(X) \
    X(LIGHT_AREA,        0, 0u,              0u,                              area)        \
    X(LIGHT_POINT,       1, KF_DELTA_LIGHTS, LT_DELTA,                        point)       \
    X(LIGHT_DIRECTIONAL, 2, KF_DELTA_LIGHTS, LT_DELTA | LT_INFINITE,          directional) \
    X(LIGHT_SPOT,        3, KF_DELTA_LIGHTS, LT_DELTA | LT_CONE,              spot)        \
    X(LIGHT_ENV,         4, KF_ENV_MAP,      LT_INFINITE,                     environment) \
    X(LIGHT_INSTANCED,   5, KF_INSTANCES,    0u,                              instanced)   \
    X(LIGHT_MOVING,      6, KF_MOTION,       0u,                              moving)

/* Traits of a light type. */
#define LT_DELTA 1u     /* a single direction reaches a point from it: no MIS, hard
                         * shadows, never hit by a ray */
#define LT_INFINITE 2u  /* infinitely far: its light arrives from a direction, not a point */
#define LT_CONE 4u      /* lights only a cone around its direction */

#define LIGHT_ENUM_(name, value, bit, traits, keyword) name = value,
enum LightType { LIGHT_TYPES(LIGHT_ENUM_) };
#undef LIGHT_ENUM_

/* Whether light type `type` has trait `trait` (LT_*). */
KFN int light_has(uint type, uint trait)
{
#define LIGHT_HAS_(name, value, bit, traits, keyword) \
    if (((traits) & trait) != 0u && type == (value)) return 1;
    LIGHT_TYPES(LIGHT_HAS_)
#undef LIGHT_HAS_
    return 0;
}
KFN int light_is_delta(uint type) { return light_has(type, LT_DELTA); }

/* The kernel feature (KF_*) the code of light type `type` is compiled under; 0: always
 * compiled in. */
KFN uint light_feature(uint type)
{
#define LIGHT_FEATURE_(name, value, bit, traits, keyword) if (type == (value)) return bit;
    LIGHT_TYPES(LIGHT_FEATURE_)
#undef LIGHT_FEATURE_
    return 0u;
}

/* Every light, in one array with a cumulative distribution for choosing one
 * proportionally to its estimated power (host/scene/scene.c). Area lights come first
 * (RenderParams.n_area_lights of them: the world's emissive primitives, then the
 * instanced ones, LIGHT_INSTANCED), then the delta lights, then the environment
 * map's light (LIGHT_ENV, RenderParams.bg_light) when the background is a map with any
 * light in it; its other fields are unused (kernels/light/envmap.h reads the map).
 * A delta light's `intensity` is radiant intensity (point, spot: W/sr) or irradiance
 * (directional: W/m^2 across the beam); point and spot lights are divided by the
 * attenuation atten0 + atten1*d + atten2*d^2 at distance d (inverse square: 0 0 1). */
typedef struct {                                        /* 96 bytes */
    uint type;                /* enum LightType */
    uint prim;                /* area lights: global primitive id; else NO_INDEX */
    float cdf;                /* P(choose a light with index <= this one) */
    float pick_pdf;           /* P(choose this light) */
    float area;               /* area lights */
    float atten0, atten1, atten2;
    vec3 position;  float cos_outer;   /* spot: no light outside this cone (cosine) */
    vec3 direction; float cos_inner;   /* unit, where the light goes; spot: full inside */
    vec3 intensity; uint quad;        /* LIGHT_QUAD_* (triangle lights, below) */
    vec3 normal;    uint spot_falloff;  /* triangle lights: the unit normal surface_at
                                         * gives the triangle, kept so that a light
                                         * sample (15% of the scalar device's time on the
                                         * Cornell box) need not build it each time;
                                         * spot: enum SpotFalloff */
} Light;

/* How a spot light fades between its inner and outer cones, c the cosine of the angle
 * from its axis. SPOT_SMOOTHSTEP: smoothstep(cos_outer, cos_inner, c), as pbrt-v4's
 * SpotLight (clpt's own `spot` and pbrt scenes). SPOT_GLTF: KHR_lights_punctual's
 * reference rule, the square of the linear ramp clamp((c - cos_outer) / max(1e-3,
 * cos_inner - cos_outer), 0, 1), which falls faster before levelling off. */
enum SpotFalloff { SPOT_SMOOTHSTEP = 0, SPOT_GLTF = 1 };

/* Two triangle lights that are the halves of one parallelogram (a quad lamp split in
 * two, as OBJ, PLY and glTF quads are), of one material and next to each other in the
 * list, are marked LIGHT_QUAD_FIRST and LIGHT_QUAD_SECOND and get equal choice
 * probabilities; both then hold the parallelogram in the delta-light fields they do not
 * use: `position` a corner, `direction` and `intensity` its two edges from it. With the
 * Sobol sampler's light pair, the pair's first coordinate then runs across the whole
 * quad (lights.h), so its 2D points stay stratified over the lamp instead of being
 * split between two triangles and warped by each. */
#define LIGHT_QUAD_NONE 0u
#define LIGHT_QUAD_FIRST 1u
#define LIGHT_QUAD_SECOND 2u

/* A LIGHT_INSTANCED light is triangle `prim` of an object (its own material's emission)
 * carried to the world by one instance's M, computed once on the host in double: its
 * world `area` and unit `normal` (M^-T of the winding normal, the side surface_at gives
 * a hit through the instance), and in `position`, `direction` and `intensity` its world
 * corner p0 and edges p1 - p0, p2 - p0, or, for the halves of a quad (`quad`), the world
 * parallelogram as above. An affine map keeps a uniform density on a triangle uniform,
 * so a point sampled on the world triangle has density 1 / area, as the hit's
 * light_pdf reads (kernels/light/lights.h). A hit through instance i on a triangle whose
 * `light` is j (its index among its object's emitters) is light instance_lights[i] + j
 * (scene_buffers.h; NO_INDEX there: the instance's triangles are no lights).
 *
 * A LIGHT_MOVING light is the same emitter of an instance that moves: it has no one
 * world place, so the record keeps the object-space one and the instance, and the
 * kernels place it at the path's time with the very transform a ray into that instance
 * gets then (light_moving_at, kernels/light/lights.h: the LIGHT_INSTANCED record of
 * that moment). `position`, `direction` and `intensity` hold the object-space corner
 * and edges (or the parallelogram of a quad's halves, `quad`), `normal` the
 * object-space winding normal (a sphere: centre in `position`, radius in `atten0`), and
 * the word a spot light's falloff takes holds the instance (light_instance). `area` is
 * the area of the instance's first pose (a sphere's: its object-space area; the
 * sample's density uses the area at the path's time); the choice's power is the mean area's over the shutter, on the host
 * (host/scene/scene_lights.c). A sphere is a light only when every key of its instance
 * is a similarity (else its `area` is 0: never chosen). */

/* The instance that carries LIGHT_MOVING light l (above). */
KFN uint light_instance(Light l) { return l.spot_falloff; }

enum CameraType { CAMERA_PERSPECTIVE = 0, CAMERA_ORTHOGRAPHIC = 1 };

/* A camera prepared on the host. Perspective (thin lens): the ray through film position
 * (s, t) in [0,1]^2 (t = 0 at the top row) starts at origin + lens offset and passes
 * through corner + s*horizontal - t*vertical (corner is the top-left of the focus
 * plane). Orthographic: the ray starts at corner + s*horizontal - t*vertical (a
 * rectangle through the camera centre) and goes along `forward`. */
/* A moving camera (motion_keys > 0, docs/motion.md) is prepared in its own space, the
 * frame of its first key: each path draws a time in [shutter_open, shutter_close] and
 * its ray is carried to the world by the camera's transform at that time, interpolated
 * between motion_keys MotionKey records from motion_first on (kernels/geom/motion.h).
 * A still camera (motion_keys 0, the shutter unread) is prepared in the world. */
typedef struct {                                        /* 112 bytes */
    vec3 origin;      float lens_radius;
    vec3 corner;      uint type;
    vec3 horizontal;  float shutter_open;
    vec3 vertical;    float shutter_close;
    vec3 lens_u;      uint motion_first;  /* unit vectors spanning the lens plane; the
                                           * camera's first key in motion_keys[] */
    vec3 lens_v;      uint motion_keys;   /* its keys; 0: the camera does not move */
    vec3 forward;     uint moving;  /* unit view direction; moving: 1 when anything in
                                     * the scene moves (the camera or an instance):
                                     * each path draws its time (PathState.time) */
} Camera;

/* One key of an animated transform (kernels/geom/motion.h): the transform at `time`
 * decomposed as M = T R S, pbrt-v4's AnimatedTransform (PBR 4th ed., 3.10.1, after
 * Shoemake and Duff, "Matrix Animation and Polar Decomposition", 1992): the
 * translation T, the rotation R as a unit quaternion (x, y, z, w; the host flips its
 * sign where that makes the arc to the next key the shorter) and the symmetric stretch
 * S (its upper triangle: s00 s01 s02 s11 s12 s22). Between two keys T and S are
 * interpolated linearly and R by slerp. A transform's keys are consecutive records in
 * increasing time. */
typedef struct {                                        /* 64 bytes */
    float time;       vec3 translate;
    float rotate[4];
    float stretch[6];
    uint count;       /* the keys of its transform (the same in each of them) */
    float pad1;
} MotionKey;

/* Textures (kernels/material/texture.h), in one table; image texels live in one uint array. */
enum TextureType {
    TEX_IMAGE = 0,       /* bilinear lookup of width x height texels at offset */
    TEX_CHECKER = 1      /* color0/color1 alternating on unit cells of texture space */
};
#define TEX_SRGB 1u      /* 8-bit texels are sRGB-encoded: decoded before filtering */
#define TEX_FLOAT 4u     /* texels are 3 floats (as uint bits) each; else packed RGBA8 */
#define TEX_SOLID 8u     /* checker: at the 3D hit point; else at the surface (u, v) */
/* Wrap modes, per axis (glTF's wrapS is u, wrapT v): outside [0,1] a coordinate repeats
 * unless its axis clamps to the edge or mirrors (every other period flipped, as
 * GL_MIRRORED_REPEAT); clamp wins over mirror when both are set. */
#define TEX_CLAMP_U 2u
#define TEX_CLAMP_V 32u
#define TEX_CLAMP (TEX_CLAMP_U | TEX_CLAMP_V)
#define TEX_MIRROR_U 64u
#define TEX_MIRROR_V 128u
#define TEX_NEAREST 256u /* the nearest texel instead of bilinear filtering */
#define TEX_UV1 512u     /* looked up at the second uv set (TriExtra) where a triangle has one */
/* With TEX_FLOAT: the texels are one word each, Radiance's RGBE (rgbe_decode in
 * texture.h), packed by render_scene_prepare where that keeps every value (texel_pack.h) */
#define TEX_RGBE 1024u
/* How a texture is read rather than what its texels are: a copy over other texels
 * (glTF's tinted base colour) keeps these. */
#define TEX_SAMPLING (TEX_CLAMP | TEX_MIRROR_U | TEX_MIRROR_V | TEX_NEAREST | TEX_UV1)

typedef struct {                                        /* 112 bytes */
    uint type;                /* enum TextureType */
    uint flags;               /* TEX_* */
    uint offset;              /* first uint of the image in texels[] */
    uint width;
    uint height;
    uint pad0, pad1, pad2;
    float m[12];              /* 3x4 row-major map to texture space: of (x, y, z, 1) for
                               * TEX_SOLID, else of (u, v, 0, 1) */
    vec3 color0;  float pad3;
    vec3 color1;  float pad4;
} Texture;

enum BackgroundType { BG_CONSTANT = 0, BG_SKY = 1, BG_CUBEMAP = 2, BG_MAP = 3 };

/* A cube-map background is six consecutive image textures from
 * RenderParams.bg_cubemap on, in the course's order (kernels/light/background.h). */
enum CubeFace { CUBE_LEFT = 0, CUBE_RIGHT = 1, CUBE_UP = 2, CUBE_DOWN = 3, CUBE_FRONT = 4, CUBE_BACK = 5 };

/* What a sample computes: light transport (path, whitted), an auxiliary image of the
 * first hit, or a feature image of the denoiser (kernels/integrator/whitted.h). */
enum Integrator {
    INTEGRATOR_PATH = 0,
    INTEGRATOR_WHITTED = 1,
    INTEGRATOR_AOV_NORMAL = 2,   /* shading normal n as (n + 1) / 2 */
    INTEGRATOR_AOV_DEPTH = 3,    /* (distance, 1, 0) at a hit, 0 0 0 for a miss */
    INTEGRATOR_AOV_ALBEDO = 4,   /* diffuse colour (textured) */
    /* the denoiser's features (--denoise, docs/denoise.md): as the two above, but at the
     * first surface that is not perfectly specular, seen through mirrors and clear glass */
    INTEGRATOR_FEATURE_NORMAL = 5,
    INTEGRATOR_FEATURE_ALBEDO = 6,
    /* what the path integrator's camera ray sees emitted at its first hit (or the
     * background where it escapes), along the path integrator's own camera rays: the
     * part of the image the denoiser is not given (host/render/passes.c) */
    INTEGRATOR_FEATURE_EMISSION = 7
};

/* A participating medium (kernels/medium/, docs/media.md): coefficients per unit of
 * scene length, per RGB channel, already times the scene's `scale`. Homogeneous media
 * are these constants everywhere they are bound. */
enum MediumType { MEDIUM_HOMOGENEOUS = 0, MEDIUM_GRID = 1 };
typedef struct {                                        /* 64 bytes */
    uint type;                /* enum MediumType */
    float g;                  /* Henyey-Greenstein asymmetry in (-1, 1); |g| < 1e-3 is
                               * stored as 0 (the sampling formula divides by g) */
    uint grid;                /* MEDIUM_GRID: its GridMedium in grids[] */
    uint flags;               /* MEDIUM_* flags */
    vec3 sigma_a;  float pad2;   /* absorption; MEDIUM_GRID: per unit of density */
    vec3 sigma_s;  float pad3;   /* scattering; MEDIUM_GRID: per unit of density */
    vec3 emission; float pad4;   /* radiance Le (pbrt-v4's Le times Lescale): a stretch
                               * ds emits sigma_a Le ds (medium_emitted, grid_emitted);
                               * MEDIUM_GRID: times the cell's emission scale and
                               * its blackbody colour (GridMedium.temperature_at); with
                               * MEDIUM_EMISSIVE set in flags when not 0 0 0 */
} Medium;

/* The interior of a subsurface material (docs/subsurface.md): its stops are the steps of
 * a random walk, which cost no bounce of the path's depth (they count as crossings,
 * against MEDIUM_MAX_WALK), sample no light (a light sample from inside the closed
 * surface is blocked by it) and take Russian roulette by the throughput alone. */
#define MEDIUM_WALK 1u
/* The medium emits (Medium.emission is not 0 0 0): its flights add sigma_a Le
 * (medium_emitted, grid_emitted; docs/media.md, "Emission"). */
#define MEDIUM_EMISSIVE 2u

/* A heterogeneous medium's density (kernels/medium/grid.h, docs/media.md): nx ny nz
 * values, x fastest, at the centres of the cells of its box, trilinearly interpolated
 * (clamped to the outermost centres, as Mitsuba 3's gridvolume), 0 outside the box;
 * and a coarse majorant grid of mx my mz cells, each the largest density the
 * interpolation takes in it, which delta and ratio tracking walk cell by cell, and a
 * minorant grid of the same cells (the smallest), residual ratio tracking's control. Both
 * live in grid_data[] from their offsets. Medium.sigma_a / sigma_s are per unit of
 * density. */
typedef struct {                                        /* 96 bytes */
    float to_grid[12];        /* world point -> the box's unit cube [0, 1]^3: a 3x4
                               * affine matrix, row by row */
    uint nx, ny, nz, density_at;    /* the density's size; its offset in grid_data */
    uint mx, my, mz, majorant_at;   /* the majorant grid's size; its offset */
    float max_density;        /* the largest of all (0: the grid is empty) */
    uint emission_at;         /* the offset in grid_data of nx ny nz emission scales
                               * (pbrt-v4's "Lescale" grid), trilinear as the density;
                               * 0 when there is none (scale 1 everywhere): offset 0
                               * is the first grid's densities, never an emission grid */
    uint temperature_at;      /* the offset in grid_data of nx ny nz temperatures in kelvin
                               * (pbrt-v4's temperature grid, its offset and scale applied),
                               * trilinear as the density, then the blackbody table of
                               * GridBlackbody; the cell's blackbody colour multiplies
                               * Medium.emission. 0 when there is none (colour 1 1 1) */
    uint minorant_at;         /* the offset in grid_data of mx my mz minorants, after the
                               * majorants: each the smallest sample the interpolation
                               * blends in the cell, the control extinction of residual
                               * ratio tracking (grid_transmittance_residual) */
} GridMedium;

/* A temperature grid's blackbody table (kernels/medium/grid.h, grid_blackbody): after
 * the grid's nx ny nz kelvin values in grid_data, one float (GRID_BLACKBODY_STEPS - 1)
 * / t_max, t_max the grid's hottest value, then GRID_BLACKBODY_STEPS RGB triples, the
 * colour of pbrt-v4's BlackbodySpectrum at kelvin k t_max / (GRID_BLACKBODY_STEPS - 1),
 * k = 0, 1, ...; linear between them. At or below GRID_TEMPERATURE_CUTOFF kelvin
 * nothing glows (pbrt-v4's fixed cutoff). */
#define GRID_BLACKBODY_STEPS 4096u
#define GRID_TEMPERATURE_CUTOFF 100.0f

/* Which strategies the path integrator combines for area lights: both with the power
 * heuristic, or one alone (tests/test_mis.c checks that all three agree). */
enum MisMode { MIS_BOTH = 0, MIS_LIGHT_ONLY = 1, MIS_BSDF_ONLY = 2 };

/* Where a path's random numbers come from (kernels/sample/rng.h, --sampler). */
enum Sampler { SAMPLER_SOBOL = 0, SAMPLER_INDEPENDENT = 1 };

/* Everything constant over a render, uploaded once per device. */
typedef struct {                                        /* 352 bytes */
    Camera camera;
    vec3 bg_color;    uint bg_type;   /* constant colour, the sky's horizon colour, or
                                       * BG_MAP: the map's scale (intensity) */
    vec3 bg_zenith;   uint bg_cubemap;  /* sky colour straight up (+y); BG_CUBEMAP: the
                                       * texture index of its first face (CUBE_LEFT);
                                       * BG_MAP: the map's texture (kernels/light/envmap.h) */
    uint width, height;
    uint max_depth;                   /* longest path, in bounces after the camera ray */
    uint rr_depth;                    /* Russian roulette starts at this bounce */
    uint seed;
    uint n_spheres, n_triangles, n_boxes, n_planes;
    uint n_lights;
    uint n_nodes, n_leaf_prims;
    vec3 bounds_lo;   uint n_revsurfaces; /* box of the tree's root; RevSurface count */
    vec3 bounds_hi;   uint sampler;   /* enum Sampler */
    /* integrators and light kinds of the classic ray tracer (kernels/integrator/whitted.h) */
    vec3 ambient;     uint integrator;  /* whitted: ambient light; enum Integrator */
    uint mis_mode;                    /* enum MisMode */
    uint n_area_lights;               /* lights[0 .. n_area_lights) are area lights */
    uint n_textures;
    uint pixel_list_size;             /* 0: a batch's samples cover every pixel; else only
                                       * the pixels pixel_list names, this many (the noise
                                       * threshold's pixels still rendering, whitted's
                                       * adaptive pass; batch_pixel, scene_view.h) */
    uint strata;                      /* whitted pixel samples: 0 the pixel centre, 1
                                       * uniform jitter, m >= 2 an m x m jittered grid */
    uint sample_offset;               /* whitted: added to the sample index (adaptive
                                       * pass); path: with sample_step, see below */
    uint shadows;                     /* 0: lights are never occluded (no shadow rays,
                                       * as the course ray casters; --shadows off) */
    uint normal_miss_grey;            /* the normal image's misses: (0 + 1) / 2 grey (the
                                       * courses' convention, classic scenes), else black */
    float bg_rot_cos, bg_rot_sin;     /* BG_MAP: cos and sin of its rotation about +y */
    uint n_bvh_nodes;                 /* nodes of the 8-wide BVH, when there is one */
    uint bg_light;                    /* BG_MAP: its light in lights[] (sampled by
                                       * next-event estimation), or NO_INDEX */
    uint split;                       /* path: continuations per camera sample from its
                                       * first hit (>= 1; shade_path.h, first-hit splitting) */
    uint sample_step;                 /* path, when > 1: a batch's sample s is the pixel's
                                       * sample s * step + sample_offset (the noise
                                       * threshold renders its even and odd halves so) */
    float clamp_indirect;             /* path, when > 0: no channel of light that reached
                                       * the camera through two or more bounces passes
                                       * it, per sample (--clamp; shade_path.h) */
    /* A crop (--crop, --pixel-bounds, pbrt's cropwindow): the film is the width x height
     * window of a larger image, which leaves crop_left columns out on its left,
     * crop_right on its right, crop_top rows above and crop_bottom below. Samples are
     * numbered and placed by the whole image's pixel (params_image_pixel), so the
     * window's pixels are the whole render's, bit for bit. All 0: no crop. */
    uint crop_left;
    uint crop_top, crop_right, crop_bottom;
    uint n_instances;                 /* Instance records (docs/instancing.md); 0: one level */
    /* participating media (kernels/medium/, docs/media.md) */
    uint has_media;                   /* HAS_MEDIA_*: paths may meet media or
                                       * boundaries (MAT_INTERFACE); 0: the code of
                                       * KF_MEDIA is skipped, and images are those of
                                       * before media */
    uint n_media;                     /* entries of media[] */
    uint camera_medium;               /* where camera rays start: 0 vacuum, else 1 +
                                       * an index into media[] */
    uint n_grids;                     /* entries of grids[] (MEDIUM_GRID media) */
    uint has_alpha;                   /* 1: some material may be cut out (alphaMode MASK
                                       * or BLEND, kernels/accel/alpha.h); 0: no hit
                                       * looks its material up for it (the scalar
                                       * device's builds have KF_ALPHA for every scene) */
    uint env_mis_dist;                /* BG_MAP: where in env_cdf the compensated
                                       * distribution starts, which MIS-weighted light
                                       * samples draw from; 0: the map's own serves
                                       * (kernels/light/envmap.h) */
    uint pad1, pad2;                  /* to a multiple of 16 bytes */
} RenderParams;

#define HAS_MEDIA_ANY 1u          /* RenderParams.has_media: some medium or boundary */
#define HAS_MEDIA_WALK 2u         /* ... and some subsurface walk (MEDIUM_WALK) */

/* One path of the wavefront; lives in a device buffer between kernel launches. */
typedef struct {                                        /* 80 bytes */
    vec3 throughput;  uint pixel;
    vec3 radiance;    uint sample;
    vec3 shadow_L;    uint bounce;    /* contribution waiting for its shadow ray */
    float bsdf_pdf;                   /* solid-angle pdf of the last bounce (MIS) */
    uint flags;                       /* PATH_* */
    uint rng_key;                     /* RngKey.key of the camera sample (rng.h) */
    uint branch;                      /* which of RenderParams.split continuations from
                                       * the first hit this is (path_branch_next) */
    uint medium;                      /* the medium the ray travels in: 0 vacuum, else
                                       * 1 + an index into media[] (kernels/medium/) */
    uint shadow_medium;               /* ... the one the shadow ray starts in */
    uint crossings;                   /* boundaries passed straight through
                                       * (MAT_INTERFACE): the random numbers of a bounce
                                       * are those of bounce + crossings, so the segment
                                       * after a boundary draws fresh ones */
    float time;                       /* the path's time in the shutter (Camera.moving;
                                       * else 0): every ray of the path sees the scene
                                       * then (SceneView.time) */
} PathState;

#define PATH_SPECULAR 1u      /* last bounce was a delta lobe: no MIS on emission */

/* The wavefront's queue counters (entry.cl) are spaced this many uints apart, one per
 * 64-byte cache line, so that the two counters k_shade adds to atomically and the
 * counts the host reads back never share a line. */
#define QUEUE_COUNT_STRIDE 16u

/* Stage results reported by shade_path to its caller, which does the queueing. */
#define SHADE_CONTINUE 1u     /* the path goes on with the ray written back */
#define SHADE_SHADOW 2u       /* a shadow ray was written; shadow_L waits on it */
#define SHADE_SCATTERED 4u    /* the surface scatters (a BSDF was sampled, whether or not
                               * the sample went on), or the camera ray's first hit is a
                               * medium's boundary and the path crossed it: at the
                               * first hit, the path splits */

#ifndef KERNEL_OPENCL
#include <stddef.h>
#define CLPT_CHECK_SIZE(T, n) _Static_assert(sizeof(T) == (n), #T " must be " #n " bytes")
/* One line a struct's size or a field's offset: a declarative list, alike by design. */
CLPT_CHECK_SIZE(vec3, 12);
CLPT_CHECK_SIZE(Ray, 32);
CLPT_CHECK_SIZE(Hit, 32);
_Static_assert(offsetof(Hit, inst) == 16, "Hit.inst");
CLPT_CHECK_SIZE(Instance, 108);
_Static_assert(offsetof(Instance, root) == 96, "Instance.root");
_Static_assert(offsetof(RenderParams, n_instances) == 316, "RenderParams.n_instances");
CLPT_CHECK_SIZE(KdNode, 8);
CLPT_CHECK_SIZE(BvhNode, 256);
CLPT_CHECK_SIZE(BvhTopNode, 96);
_Static_assert(offsetof(BvhTopNode, ref) == 64, "BvhTopNode.ref");
CLPT_CHECK_SIZE(KdProto, 32);
_Static_assert(offsetof(KdProto, hi) == 16, "KdProto.hi");
CLPT_CHECK_SIZE(Sphere, 32);
CLPT_CHECK_SIZE(SphereXform, 96);
_Static_assert(offsetof(Sphere, xform) == 24, "Sphere.xform");
_Static_assert(offsetof(SphereXform, to_object) == 48, "SphereXform.to_object");
CLPT_CHECK_SIZE(Triangle, 48);
CLPT_CHECK_SIZE(TriShading, 64);
CLPT_CHECK_SIZE(TriExtra, 128);
_Static_assert(offsetof(TriExtra, uv) == 96, "TriExtra.uv");
CLPT_CHECK_SIZE(Box, 32);
CLPT_CHECK_SIZE(Plane, 32);
CLPT_CHECK_SIZE(RevSurface, 48);
CLPT_CHECK_SIZE(Material, 320);
CLPT_CHECK_SIZE(Light, 96);
CLPT_CHECK_SIZE(Camera, 112);
CLPT_CHECK_SIZE(MotionKey, 64);
_Static_assert(offsetof(Camera, motion_keys) == 92, "Camera.motion_keys");
_Static_assert(offsetof(PathState, time) == 76, "PathState.time");
_Static_assert(offsetof(MotionKey, stretch) == 32, "MotionKey.stretch");
CLPT_CHECK_SIZE(RenderParams, 352);
CLPT_CHECK_SIZE(PathState, 80);
CLPT_CHECK_SIZE(Medium, 64);
CLPT_CHECK_SIZE(GridMedium, 96);
CLPT_CHECK_SIZE(Texture, 112);
_Static_assert(offsetof(RenderParams, bg_color) == 112, "RenderParams.bg_color");
_Static_assert(offsetof(RenderParams, width) == 144, "RenderParams.width");
_Static_assert(offsetof(RenderParams, bounds_lo) == 192, "RenderParams.bounds_lo");
_Static_assert(offsetof(RenderParams, ambient) == 224, "RenderParams.ambient");
_Static_assert(offsetof(RenderParams, strata) == 256, "RenderParams.strata");
_Static_assert(offsetof(RenderParams, shadows) == 264, "RenderParams.shadows");
_Static_assert(offsetof(RenderParams, normal_miss_grey) == 268, "RenderParams.normal_miss_grey");
_Static_assert(offsetof(RenderParams, bg_light) == 284, "RenderParams.bg_light");
_Static_assert(offsetof(RenderParams, crop_left) == 300, "RenderParams.crop_left");
_Static_assert(offsetof(Material, reflective) == 64, "Material.reflective");
_Static_assert(offsetof(Light, cos_inner) == 60, "Light.cos_inner");
_Static_assert(offsetof(Texture, m) == 32, "Texture.m");
_Static_assert(offsetof(Texture, color1) == 96, "Texture.color1");
_Static_assert(offsetof(PathState, bsdf_pdf) == 48, "PathState.bsdf_pdf");
_Static_assert(offsetof(Material, albedo) == 16, "Material.albedo");
_Static_assert(offsetof(Material, roughness) == 60, "Material.roughness");
_Static_assert(offsetof(Material, k) == 112, "Material.k");
_Static_assert(offsetof(Material, clearcoat_roughness) == 128, "Material.clearcoat_roughness");
_Static_assert(offsetof(Material, texture_rm) == 132, "Material.texture_rm");
_Static_assert(offsetof(Material, normal_scale) == 140, "Material.normal_scale");
_Static_assert(offsetof(Material, mix_a) == 160, "Material.mix_a");
_Static_assert(offsetof(Material, absorption) == 176, "Material.absorption");
_Static_assert(offsetof(Material, sheen_color) == 208, "Material.sheen_color");
_Static_assert(offsetof(Material, texture_sheen_roughness) == 232, "Material.texture_sheen_roughness");
_Static_assert(offsetof(Material, layer_albedo) == 240, "Material.layer_albedo");
_Static_assert(offsetof(Material, base_roughness) == 272, "Material.base_roughness");
_Static_assert(offsetof(Light, position) == 32, "Light.position");
_Static_assert(offsetof(Material, medium_in) == 280, "Material.medium_in");
_Static_assert(offsetof(Material, diffuse_transmission) == 236, "Material.diffuse_transmission");
_Static_assert(offsetof(Material, diffuse_transmission_color) == 288, "Material.diffuse_transmission_color");
_Static_assert(offsetof(RenderParams, has_media) == 320, "RenderParams.has_media");
_Static_assert(offsetof(RenderParams, has_alpha) == 336, "RenderParams.has_alpha");
_Static_assert(offsetof(PathState, medium) == 64, "PathState.medium");
_Static_assert(offsetof(Medium, sigma_s) == 32, "Medium.sigma_s");
_Static_assert(offsetof(Medium, emission) == 48, "Medium.emission");
_Static_assert(offsetof(GridMedium, nx) == 48, "GridMedium.nx");
_Static_assert(offsetof(GridMedium, max_density) == 80, "GridMedium.max_density");
_Static_assert(offsetof(GridMedium, emission_at) == 84, "GridMedium.emission_at");
_Static_assert(offsetof(GridMedium, temperature_at) == 88, "GridMedium.temperature_at");
_Static_assert(offsetof(GridMedium, minorant_at) == 92, "GridMedium.minorant_at");
#undef CLPT_CHECK_SIZE
#endif

#endif /* CLPT_TYPES_H */
