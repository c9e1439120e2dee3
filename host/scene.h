/*
 * scene.h — the scene as the host holds it: camera and image settings as written in the
 * scene file, named materials, and the primitive arrays in the exact layout the kernels
 * read (kernels/types.h), so uploading is a copy.
 */
#ifndef CLPT_SCENE_H
#define CLPT_SCENE_H

#include <stddef.h>

#include "status.h"
#include "types.h"

typedef struct {
    vec3 from, at, up;
    float vfov;          /* vertical field of view, degrees */
    float aperture;      /* lens diameter; 0 is a pinhole */
    float focus_dist;    /* distance to the plane in focus; <= 0 means |at - from| */
} SceneCamera;

typedef struct {
    uint width, height;
    uint spp;            /* samples per pixel */
    uint max_depth;      /* bounces after the camera ray */
    uint seed;
} SceneImage;

typedef struct {
    char *path;                  /* scene file as given on the command line */
    SceneCamera camera;
    SceneImage image;
    uint bg_type;                /* enum BackgroundType */
    vec3 bg_color, bg_zenith;

    Material *materials;   char **material_names;  size_t n_materials, cap_materials;
    /* Per material: the albedo texture file a mesh's MTL names (map_Kd, resolved to a
     * path), or NULL; n_material_textures <= n_materials (missing entries are NULL). */
    char **material_textures;  size_t n_material_textures;
    Sphere *spheres;       size_t n_spheres, cap_spheres;
    Triangle *triangles;   size_t n_triangles, cap_triangles;
    TriShading *shading;   size_t n_shading, cap_shading;
    Box *boxes;            size_t n_boxes, cap_boxes;
    Plane *planes;         size_t n_planes, cap_planes;
    Light *lights;         size_t n_lights;     /* filled by scene_prepare_lights */
} Scene;

/* Defaults: 512x512, 64 spp, depth 8, seed 1, black background, camera at the origin
 * looking down -z with a 40 degree field of view. */
void scene_init(Scene *s);
void scene_free(Scene *s);

/* Reads a scene file (docs/scene-format.md) into an initialised scene. */
Status scene_load(const char *path, Scene *s, Error *err);

/* Appending; each fails only when memory runs out (ST_INTERNAL). */
Status scene_add_material(Scene *s, const char *name, Material m, uint *index, Error *err);
Status scene_add_sphere(Scene *s, Sphere sp, Error *err);
Status scene_add_triangle(Scene *s, Triangle t, Error *err);
Status scene_add_shading(Scene *s, TriShading sh, uint *index, Error *err);
Status scene_add_box(Scene *s, Box b, Error *err);
Status scene_add_plane(Scene *s, Plane p, Error *err);

/* Records `path` (copied) as the albedo texture file of material `index`. */
Status scene_set_material_texture(Scene *s, uint index, const char *path, Error *err);
/* The texture file of material `index`, or NULL. */
const char *scene_material_texture(const Scene *s, uint index);

/* Index of the material with this name, or NO_INDEX. */
uint scene_find_material(const Scene *s, const char *name);

/* Global primitive id of the first triangle, box and plane (spheres start at 0). */
uint scene_first_triangle(const Scene *s);
uint scene_first_box(const Scene *s);
uint scene_first_plane(const Scene *s);

/* Builds the light list from the emissive spheres, triangles and boxes (choice
 * probability proportional to area x luminance) and sets each primitive's `light`. */
Status scene_prepare_lights(Scene *s, Error *err);

/* Material helpers with the defaults of docs/scene-format.md. */
Material material_diffuse(vec3 albedo);
Material material_metal(vec3 albedo, float fuzz);
Material material_dielectric(float ior);
Material material_emissive(vec3 radiance);

/* Grows *ptr (an array of `elem`-byte items with capacity *cap) to hold `need` items.
 * Returns 0 on success, -1 when out of memory (the array is then unchanged). */
int array_reserve(void **ptr, size_t *cap, size_t need, size_t elem);

#endif /* CLPT_SCENE_H */
