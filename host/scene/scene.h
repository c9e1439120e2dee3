/*
 * scene.h — the scene as the host holds it: camera and image settings as written in the
 * scene file, named materials, and the primitive arrays in the exact layout the kernels
 * read (kernels/types.h), so uploading is a copy.
 */
#ifndef CLPT_SCENE_H
#define CLPT_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "base/status.h"
#include "base/strmap.h"
#include "types.h"
#include "scene/animation.h"
#include "scene/crop.h"
#include "scene/transform.h"

typedef struct {
    vec3 from, at, up;
    float vfov;          /* vertical field of view, degrees */
    float aperture;      /* lens diameter; 0 is a pinhole */
    float focus_dist;    /* distance to the plane in focus; <= 0 means |at - from| */
    uint type;           /* enum CameraType */
    float ortho_height;  /* orthographic: height of the view rectangle (world units) */
    float ortho_width;   /* orthographic: > 0, the view rectangle's width instead (clpt's
                          * format: it holds whatever --width and --height make the
                          * image), its height following the image's shape */
    int course_basis;    /* perspective: span the image with normalize(view x up) and
                          * `up` as given (MIT 6.837 Fall 2019), not an orthonormal frame */
    int mirror_x;        /* the image's right is -(view x up): a left-handed camera frame,
                          * as pbrt's LookAt makes (docs/pbrt.md) */
    float shutter_open, shutter_close;   /* the times a moving scene is seen over
                                          * (docs/motion.md); 0 and 1 by default */
    float time;          /* the time of this pose when the camera moves (Scene.camera_keys) */
} SceneCamera;

/* A later pose of a moving camera (docs/motion.md): where it is at `time`, its other
 * settings the camera's own. */
typedef struct {
    float time;
    vec3 from, at, up;
} SceneCameraKey;

/* The tree the kernels find primitives through (host/accel): the 8-wide BVH by default
 * (faster on every bench mesh: bench/RESULTS.md), or the kd-tree. Images differ only
 * where two primitives are hit at exactly the same distance. */
enum SceneAccel { ACCEL_BVH = 0, ACCEL_KDTREE = 1 };

/* Scene.keep_animation: whether a reader keeps a file's animation (scene/animation.h),
 * and whether a file without one is an error (--frames, --time) or read as it stands
 * (--shutter: a still file with a shutter keeps its bits) */
enum { KEEP_ANIMATION_NO = 0, KEEP_ANIMATION_NEEDED = 1, KEEP_ANIMATION_IF_ANY = 2 };

typedef struct {
    uint width, height;
    uint spp;            /* samples per pixel */
    uint max_depth;      /* bounces after the camera ray */
    uint seed;
    uint sampler;        /* enum Sampler (kernels/sample/rng.h); 0, Sobol, by default */
    uint split;          /* continuations per camera sample from its first hit (1: none;
                          * SCENE_SPLIT_AUTO: chosen by a pilot render, render/split_pilot.h) */
    float clamp_indirect;  /* path: --clamp's limit on indirect light, 0 = none */
} SceneImage;
/* SceneImage.split: the render's pilot chooses (the default; render/split_pilot.h) */
#define SCENE_SPLIT_AUTO 0u

/* A material that a shape bounding media was given (scene/media.h): materials[material]
 * is materials[origin] with the media `in` and `out` (0 vacuum, 1 + a medium's index, or
 * SCENE_MEDIUM_UNSET: the background's, known only once the scene is read). */
typedef struct {
    uint material, origin, in, out;
} SceneMediumBinding;
#define SCENE_MEDIUM_UNSET 0xffffffffu

/* An object (docs/instancing.md): the primitives its block made, [first, end) of each
 * kind in the scene's arrays (spheres, triangles, boxes, surfaces of revolution, in
 * that order), which only its instances reach: no tree but its own holds them, and
 * their emitters are lights once per instance (scene_prepare_lights). Objects are made
 * one after another, so their ranges increase. */
enum { OBJ_SPHERES, OBJ_TRIANGLES, OBJ_BOXES, OBJ_REVS, OBJ_KINDS };
typedef struct {
    char *name;
    size_t first[OBJ_KINDS], end[OBJ_KINDS];
    /* the instances its block holds (nesting): [first_nested, end_nested) of the
     * scene's `nested`; an instance of this object places each of them too */
    size_t first_nested, end_nested;
    uint depth;          /* 1 for shapes alone, else 1 + its nested objects' deepest */
    uint64_t leaves;     /* the world instances one instance of it makes (held at 2^62,
                          * far past SCENE_MAX_INSTANCES, scene/instance.h) */
} SceneObject;

/* An instance inside an object's block: `object` under m (in the holder's space) with
 * `material` (NO_INDEX: its own). Resolved into world instances when the holder is
 * placed (scene_place_object, scene/instance.h), so the devices see one level. */
typedef struct {
    Transform m;
    uint object, material;
} SceneNested;

typedef struct {
    char *path;                  /* scene file as given on the command line */
    int size_overridden;         /* in: --width or --height replaces the file's size, so
                                  * the file's own is not checked against the limits
                                  * (the size rendered is, host/main.c) */
    const char *gltf_camera;     /* in: the glTF camera to look through (--camera), by
                                  * index or name; NULL: the file's first */
    int keep_animation;          /* in: a reader keeps the file's animation: KEEP_ANIMATION_*
                                  * (--frames, --time: one is needed; --shutter: if any) */
    SceneAnimation *animation;   /* out: that animation, or NULL (scene/animation.h) */
    SceneCamera camera;
    /* a moving camera's poses after its own (SceneCamera.time), in increasing time;
     * none for a camera that stands still */
    SceneCameraKey *camera_keys;  size_t n_camera_keys, cap_camera_keys;
    SceneImage image;
    SceneCrop crop;              /* the window rendered (pbrt's cropwindow, --crop ...);
                                  * CROP_NONE: the whole image */
    char *output_hint;           /* the image file the scene asks for (pbrt's Film
                                  * "filename"), used when -o is not given; NULL: none */
    uint bg_type;                /* enum BackgroundType */
    vec3 bg_color, bg_zenith;
    uint bg_cubemap;             /* BG_CUBEMAP: index of the first of its six textures;
                                  * BG_MAP: the map's texture (scene_set_envmap) */
    float bg_rotate;             /* BG_MAP: degrees about +y */
    float *env_cdf;  size_t n_env_cdf;   /* BG_MAP: its distributions (kernels/light/envmap.h) */
    size_t env_mis_dist;         /* ... where the compensated one starts, or 0 (env_dist.h) */
    double env_mean;             /* BG_MAP: mean luminance over the sphere, scaled */
    uint env_light;              /* its light in `lights`, or NO_INDEX (scene_prepare_lights) */

    Material *materials;   char **material_names;  size_t n_materials, cap_materials;
    /* Per material: the albedo texture file a mesh's MTL names (map_Kd, resolved to a
     * path), or NULL; n_material_textures <= n_materials (missing entries are NULL). */
    char **material_textures;  size_t n_material_textures;
    Sphere *spheres;       size_t n_spheres, cap_spheres;
    /* the transforms of the spheres that are ellipsoids (Sphere.xform) */
    SphereXform *sphere_xforms;  size_t n_sphere_xforms, cap_sphere_xforms;
    Triangle *triangles;   size_t n_triangles, cap_triangles;
    TriShading *shading;   size_t n_shading, cap_shading;
    /* glTF's tangents, second uvs and vertex colours (types.h, TriExtra): tri_extra_of
     * is empty until the first extra is added, then has one entry per shading record */
    TriExtra *tri_extras;  size_t n_tri_extras, cap_tri_extras;
    uint *tri_extra_of;    size_t n_tri_extra_of, cap_tri_extra_of;
    Box *boxes;            size_t n_boxes, cap_boxes;
    Plane *planes;         size_t n_planes, cap_planes;
    RevSurface *revsurfaces;  size_t n_revsurfaces, cap_revsurfaces;
    float *rev_points;     size_t n_rev_points, cap_rev_points;   /* (x, y) pairs: floats */
    Light *lights;         size_t n_lights;     /* filled by scene_prepare_lights */
    /* objects and their instances (scene/instance.h); Instance.root is the build's */
    SceneObject *objects;  size_t n_objects, cap_objects;
    Instance *instances;   size_t n_instances, cap_instances;
    uint *instance_objects;  size_t cap_instance_objects;   /* per instance, its object */
    SceneNested *nested;   size_t n_nested, cap_nested;
    /* per instance: its first light (LIGHT_INSTANCED, or LIGHT_MOVING for an instance
     * that moves; kernels/types.h), or NO_INDEX;
     * NULL when no instance has lights (scene_prepare_lights) */
    uint *instance_lights;
    /* moving instances (INST_MOTION, docs/motion.md): the first n_instance_motion
     * instances' first keys in motion_keys, or NO_INDEX for one that stands still (so
     * are the instances after them); NULL while none moves. Each moving instance's keys
     * are consecutive, in increasing time (scene/motion.h). */
    uint *instance_motion;        size_t n_instance_motion;
    MotionKey *motion_keys;       size_t n_motion_keys, cap_motion_keys;
    StrMap object_by_name;

    /* the classic ray tracer's additions (docs/classic-format.md) */
    Light *delta_lights;   size_t n_delta_lights, cap_delta_lights;  /* point, spot, directional */
    Texture *textures;     char **texture_names;  char **texture_sources;
    size_t n_textures, cap_textures;            /* names: NULL for anonymous textures;
                                                 * sources: the image file, else NULL */
    uint *texels;          size_t n_texels, cap_texels;   /* every image, Texture.offset */
    vec3 ambient;                /* whitted: ambient light (times the diffuse colour) */
    uint integrator;             /* enum Integrator the scene asks for (INTEGRATOR_PATH
                                  * or INTEGRATOR_WHITTED); --integrator overrides it */
    int linear_output;           /* 8-bit images without the sRGB curve (classic scenes) */
    uint normal_miss_grey;       /* the normal image's misses grey, not black (classic) */
    int shadows;                 /* lights can be occluded: 1 for clpt's format and meshes,
                                  * 0 for classic scenes; --shadows overrides it */
    uint accel;                  /* enum SceneAccel: the tree the rays walk (--accel) */

    /* Lookups by name, so that a scene or MTL with many materials reads in linear time:
     * material name -> first material of that name, texture name -> first texture of
     * that name, and "S" / "L" + image file -> the first texture read from it in sRGB /
     * linear encoding (texture_load_image shares its texels). */
    StrMap material_by_name, texture_by_name, texture_by_source;

    /* Participating media (scene/media.h, docs/media.md): the named media, the
     * background's (0 none, else 1 + index: the medium everywhere no boundary says
     * otherwise) and the camera's (the same, or SCENE_MEDIUM_UNSET for the
     * background's), and which materials are copies bound to media (the shapes'
     * interior and exterior), resolved by scene_prepare_media. */
    Medium *media;         char **medium_names;   size_t n_media, cap_media;
    uint world_medium, camera_medium;
    SceneMediumBinding *medium_bindings;   size_t n_medium_bindings, cap_medium_bindings;
    /* the grids of heterogeneous media (Medium.grid) and their densities and
     * majorants, as the devices get them (scene_add_grid) */
    GridMedium *grids;     size_t n_grids, cap_grids;
    float *grid_data;      size_t n_grid_data, cap_grid_data;

    /* Problems the readers worked around (a missing map_Kd image), for main to print
     * once the scene is read; each names the file and line. */
    char **warnings;       size_t n_warnings;
} Scene;

/* Defaults: 512x512, 64 spp, depth 8, seed 1, black background, camera at the origin
 * looking down -z with a 40 degree field of view. */
void scene_init(Scene *s);
void scene_free(Scene *s);

/* Reads a scene file (docs/scene-format.md) into an initialised scene. */
Status scene_load(const char *path, Scene *s, Error *err);
/* The same for `len` bytes of scene text in memory (copied), named `path` in messages;
 * included files and meshes are still read from disk, beside `path`. */
Status scene_load_text(const char *path, const char *text, size_t len, Scene *s, Error *err);

/* The file the scene was read from (for messages and relative paths), copied. */
Status scene_set_path(Scene *s, const char *path, Error *err);

/* Appending; each fails only when memory runs out (ST_INTERNAL). */
Status scene_add_material(Scene *s, const char *name, Material m, uint *index, Error *err);
Status scene_add_sphere(Scene *s, Sphere sp, Error *err);
/* The unit sphere under the affine transform m (an ellipsoid when m is not a
 * similarity), of `material`: a sphere with a SphereXform, whose centre and radius
 * bound it. ST_INPUT (message without a location) when m is singular or the ellipsoid
 * reaches beyond what floats hold. It must not emit light (scene_prepare_lights). */
Status scene_add_ellipsoid(Scene *s, const Transform *m, uint material, Error *err);
Status scene_add_triangle(Scene *s, Triangle t, Error *err);
Status scene_add_shading(Scene *s, TriShading sh, uint *index, Error *err);
/* Gives shading record `shading` the corner attributes e (sets its TRI_HAS_EXTRA). */
Status scene_add_tri_extra(Scene *s, uint shading, TriExtra e, Error *err);
Status scene_add_box(Scene *s, Box b, Error *err);
Status scene_add_plane(Scene *s, Plane p, Error *err);
/* Adds r with its profile's n_segments * degree + 1 control points (x, y pairs at xy);
 * fills r.first and r's bounds (the convex hull of the control points revolved). */
Status scene_add_revsurface(Scene *s, RevSurface r, const float *xy, Error *err);
/* A point, spot or directional light (type, position, direction, intensity, attenuation
 * and cone set by the caller; direction unit). */
Status scene_add_light(Scene *s, Light l, Error *err);
/* A texture; `name` (NULL for none) is for scene_find_texture, `source` (NULL for none)
 * the image file it was read from. Image textures' texels must already be appended
 * with scene_add_texels. */
Status scene_add_texture(Scene *s, const char *name, const char *source, Texture t, uint *index,
                         Error *err);
/* Appends n texels; *offset receives the index of the first. */
Status scene_add_texels(Scene *s, const uint *texels, size_t n, uint *offset, Error *err);
uint scene_find_texture(const Scene *s, const char *name);
/* The first texture read from image file `path` whose texels fit the encoding asked
 * for (linear or sRGB; HDR textures fit both), or NO_INDEX. */
uint scene_find_texture_source(const Scene *s, const char *path, int linear);

/* Records `path` (copied) as the albedo texture file of material `index`. */
Status scene_set_material_texture(Scene *s, uint index, const char *path, Error *err);
/* The texture file of material `index`, or NULL. */
const char *scene_material_texture(const Scene *s, uint index);

/* Records a warning (scene.warnings; past the first 20, one line says that more were
 * dropped); fails only when memory runs out. */
Status scene_warn(Scene *s, Error *err, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Index of the material with this name, or NO_INDEX. */
uint scene_find_material(const Scene *s, const char *name);

/* Global primitive id of the first triangle, box and plane (spheres start at 0). */
uint scene_first_triangle(const Scene *s);
uint scene_first_box(const Scene *s);
uint scene_first_revsurface(const Scene *s);
uint scene_first_plane(const Scene *s);

/* Makes image texture `texture` (float texels: an HDR or EXR image) the background, an
 * environment map (kernels/light/envmap.h) scaled by `intensity` and turned by `rotate`
 * degrees about +y, and builds its sampling distribution. ST_INPUT "'SOURCE': an
 * environment map must be a high-dynamic-range image (.hdr or .exr)" for 8-bit texels;
 * otherwise fails only when memory runs out. */
Status scene_set_envmap(Scene *s, uint texture, float intensity, float rotate, Error *err);

/* The same for a map made here rather than read from a file (a resampled cube map or
 * pbrt octahedral map): W x H float texels (3 per texel, as uint bits) added as a new
 * texture, then scene_set_envmap with `intensity` and no rotation. */
Status scene_set_envmap_texels(Scene *s, const uint *texels, uint width, uint height, float intensity, Error *err);

/* Builds the light list: the emissive spheres, triangles and boxes (area lights), the
 * emissive triangles of objects once per instance that keeps their material
 * (LIGHT_INSTANCED, docs/instancing.md; a moving instance's LIGHT_MOVING, placed at
 * each path's time, docs/motion.md; sets `instance_lights`), then the delta lights, then the environment map when the background is one with light in
 * it, with a choice probability proportional to each light's estimated power (area
 * lights: pi x area x luminance of the emission, the area in the world; point and spot
 * lights: the power through a sphere of the scene's radius (its instances' world boxes
 * counted) around them; directional lights: the power
 * through a disc of the scene's radius; the environment map: pi x its mean luminance x
 * the area 4 pi r^2 of a sphere of the scene's radius, as an area light of that size
 * shining inward), and sets each primitive's `light` and `env_light`. */
Status scene_prepare_lights(Scene *s, Error *err);

/* Refuses (ST_INPUT, naming `s->path` and the shape) what single precision cannot
 * render, which would otherwise come out black or missing without a word
 * (docs/scene-format.md, "Precision"):
 *   - a sphere whose radius, or distance from the camera, is above 2^62: the kernels
 *     square them;
 *   - a sphere more than 2^22 times larger than the camera's distance from its
 *     surface: the camera ray's hit loses every digit (measured: a ground sphere of
 *     radius 2e7 under a camera 1 above it renders black, 1.5e7 renders right);
 *   - triangles too small for their normals: when most of the scene's triangles (or a
 *     mesh's: scene_count_tiny_triangles) have an area but a normal whose squared
 *     length underflows in float (below 2^-140), they shade black or vanish. */
Status scene_check_precision(const Scene *s, Error *err);
/* (A triangle with a corner beyond SCENE_MAX_COORDINATE is refused too.) */
/* Of triangles [first, end): *with_area those whose corners span an area (in double),
 * *tiny those of them whose normal the kernels cannot normalise in float; *lo and *hi
 * (may be NULL) their bounds. */
void scene_count_tiny_triangles(const Scene *s, size_t first, size_t end, size_t *tiny, size_t *with_area,
                                vec3 *lo, vec3 *hi);

/* The largest |coordinate| of the corners of triangles [first, end). Beyond
 * SCENE_MAX_COORDINATE the kernels' watertight test, which multiplies two coordinate
 * differences and sums such products, overflows float: a pbrt disk of radius 1e20
 * vanished (1e19 renders right). scene_check_precision refuses such triangles, and the
 * pbrt reader its disks and cylinders, at the statement. */
#define SCENE_MAX_COORDINATE 0x1p62
double scene_triangles_reach(const Scene *s, size_t first, size_t end);

/* Material helpers with the defaults of docs/scene-format.md. */
Material material_diffuse(vec3 albedo);
Material material_metal(vec3 albedo, float fuzz);
Material material_dielectric(float ior);
Material material_emissive(vec3 radiance);
/* A GGX conductor of complex index eta + i k per channel (tint 1, isotropic). */
Material material_conductor(vec3 eta, vec3 k, float roughness);
/* A GGX conductor with Schlick's Fresnel from the reflectance at normal incidence f0. */
Material material_conductor_f0(vec3 f0, float roughness);
/* A glTF metallic-roughness material (base colour, metallic, roughness; no
 * transmission or clearcoat, ior 1.5), the glTF defaults being 1 1 1, 1, 1. */
Material material_principled(vec3 base, float metallic, float roughness);
/* Beer-Lambert sigma_a per channel for light keeping `color` of itself after `distance`
 * (KHR_materials_volume's attenuationColor and attenuationDistance; infinite: none). */
vec3 material_absorption(vec3 color, float distance);
/* pbrt-v4's coated materials (MAT_LAYERED) with pbrt's defaults: a smooth interface of
 * index 1.5, thickness 0.01, no medium (albedo 0, g 0), maxdepth 10, nsamples 1; over a
 * Lambertian base of reflectance `diffuse`, or over a conductor eta + i k (relative to
 * the outside: the kernel divides by the interface's index) of perceptual roughness
 * base_roughness. */
Material material_coated_diffuse(vec3 diffuse, float roughness);
Material material_coated_conductor(vec3 eta, vec3 k, float base_roughness, float roughness);
/* The complex index of a named metal (Ag, Al, Au, Cr, Cu, Fe, Ni, Ti; docs/scene-format.md gives the
 * source), the name `len` bytes long. Returns 0 when the name is none of them. */
int material_metal_preset(const char *name, size_t len, vec3 *eta, vec3 *k);
/* The classic Phong material: diffuse colour, specular colour and shininess, no mirror
 * or transparent part, index of refraction 1. */
Material material_phong(vec3 diffuse, vec3 specular, float shininess);
/* pbrt's mix (MAT_MIX): material b with probability amount (times texture `amount_tex`'s
 * red channel unless NO_INDEX), else material a; no emission of its own. */
Material material_mix(uint a, uint b, float amount, uint amount_tex);
/* How deeply material `index` nests mixes: 0 for one that is no mix, 1 for a mix of two
 * that are none, ...; stops counting past MIX_MAX_DEPTH + 1, and counts a mix that
 * names a material past n_materials as too deep too. */
uint scene_mix_depth(const Scene *s, uint index);
/* A light with defaults: intensity 0, inverse-square attenuation, direction -y, a spot
 * cone of 30 degrees (cos_outer) with no soft edge. */
Light light_default(uint type);

#endif /* CLPT_SCENE_H */
