/* render_scene.c — see render_scene.h. */
#include "render/render_scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh_top.h"
#include "scene/camera.h"
#include "scene/cube_env.h"
#include "scene/media.h"
#include "scene/subsurface.h"
#include "scene/instance.h"
#include "scene/texel_pack.h"

/* Russian roulette starts after this many bounces: early bounces carry most of the
 * image, so killing paths there adds noise for little time saved. 5 (Mitsuba 3's
 * rr_depth) against the earlier 3 gave 4-17% less time x squared error on the six
 * bench and peer scenes at equal samples (bench/RESULTS.md); 6 and 8 were no better
 * overall. */
#define RR_START_BOUNCE 5u

uint render_scene_strata(uint spp)
{
    if (spp <= 1u) return 0u;
    uint m = (uint)sqrt((double)spp);
    while (m * m > spp) m--;
    while ((m + 1u) * (m + 1u) <= spp) m++;
    return m * m == spp ? m : 1u;
}

void render_scene_use_kdtree(DeviceScene *ds, const KdTree *kd)
{
    ds->params.n_nodes = kd->n_nodes;
    ds->params.n_leaf_prims = kd->n_leaf_prims;
    ds->params.bounds_lo = kd->lo;
    ds->params.bounds_hi = kd->hi;
    ds->nodes = kd->nodes;
    ds->leaf_prims = kd->leaf_prims;
}

void render_scene_use_bvh(DeviceScene *ds, const Bvh *bvh)
{
    ds->params.n_bvh_nodes = bvh->n_nodes;
    if (ds->params.n_nodes == 0) {
        ds->params.bounds_lo = bvh->lo;
        ds->params.bounds_hi = bvh->hi;
    }
    ds->bvh = bvh->nodes;
    ds->bvh_leaves = bvh->leaf_prims;
    ds->n_bvh_leaves = bvh->n_leaf_prims;
    ds->bvh_top = bvh->top;
    ds->n_bvh_top = bvh->n_top;
}

/* The world's own primitives (in no object) as ranges of global ids into *out (freed
 * by the caller), *n of them. */
static Status world_ranges(const Scene *s, KdRange **out, size_t *n, Error *err)
{
    KdRange *r = malloc((OBJ_KINDS * (s->n_objects + 1) + 1) * sizeof *r);
    if (!r) return error_set(err, ST_INTERNAL, "out of memory listing the world's primitives");
    uint first[OBJ_KINDS] = { 0u, scene_first_triangle(s), scene_first_box(s), scene_first_revsurface(s) };
    size_t count[OBJ_KINDS] = { s->n_spheres, s->n_triangles, s->n_boxes, s->n_revsurfaces };
    size_t k = 0;
    for (int kind = 0; kind < OBJ_KINDS; kind++) {
        size_t at = 0;
        for (size_t i = 0; i <= s->n_objects; i++) {
            size_t stop = i < s->n_objects ? s->objects[i].first[kind] : count[kind];
            if (stop > at) r[k++] = (KdRange){ first[kind] + (uint)at, first[kind] + (uint)stop };
            if (i < s->n_objects) at = s->objects[i].end[kind];
        }
    }
    *out = r;
    *n = k;
    return ST_OK;
}

/* The two levels of a scene with objects: a prototype per object and the world's own as
 * the last, the scene's instances and one identity instance of the world's (INST_WORLD).
 * The top level is the BVH's; the prototypes are BVHs, or under --accel kdtree kd-trees
 * (accel/kd_inst.h, docs/instancing.md). */
static Status tree_build_instanced(const Scene *s, const KdInput *in, int threads, RenderScene *out, Error *err)
{
    size_t n_protos = s->n_objects + 1;
    BvhProto *protos = calloc(n_protos, sizeof *protos);
    KdRange *obj_ranges = malloc((s->n_objects + 1) * OBJ_KINDS * sizeof *obj_ranges);
    KdRange *world = NULL;
    out->instances = malloc((s->n_instances + 1) * sizeof *out->instances);
    uint *objects = malloc((s->n_instances + 1) * sizeof *objects);   /* each instance's prototype */
    Status st = ST_OK;
    if (!protos || !obj_ranges || !out->instances || !objects) {
        st = error_set(err, ST_INTERNAL, "out of memory for %zu instances", s->n_instances);
        goto done;
    }
    for (uint i = 0; i < (uint)s->n_objects; i++) {
        uint lo[OBJ_KINDS], hi[OBJ_KINDS];
        size_t n = scene_object_ranges(s, i, lo, hi);
        for (size_t r = 0; r < n; r++) obj_ranges[OBJ_KINDS * i + r] = (KdRange){ lo[r], hi[r] };
        protos[i] = (BvhProto){ obj_ranges + OBJ_KINDS * i, n };
    }
    size_t n_world = 0;
    if ((st = world_ranges(s, &world, &n_world, err))) goto done;
    protos[s->n_objects] = (BvhProto){ world, n_world };
    if (s->n_instances) {
        memcpy(out->instances, s->instances, s->n_instances * sizeof *out->instances);
        memcpy(objects, s->instance_objects, s->n_instances * sizeof *objects);
    }
    Instance w;
    memset(&w, 0, sizeof w);
    for (int i = 0; i < 3; i++) w.to_world[5 * i] = w.to_object[5 * i] = 1.0f;
    w.material = NO_INDEX;
    w.flags = INST_IDENTITY | INST_WORLD;
    objects[s->n_instances] = (uint)s->n_objects;
    out->instances[s->n_instances] = w;
    out->n_instances = s->n_instances + 1;
    /* moving instances (docs/motion.md): each one's first key, the world's none */
    if (s->instance_motion) {
        if (!(out->instance_motion = malloc(out->n_instances * sizeof *out->instance_motion))) {
            st = error_set(err, ST_INTERNAL, "out of memory for %zu instances", s->n_instances);
            goto done;
        }
        for (size_t i = 0; i < out->n_instances; i++)
            out->instance_motion[i] = i < s->n_instance_motion ? s->instance_motion[i] : NO_INDEX;
        out->ds.instance_motion = out->instance_motion;
        out->ds.n_instance_motion = (uint)out->n_instances;
    }
    BvhMotion motion = { out->instance_motion, s->motion_keys };
    int kd = s->accel == ACCEL_KDTREE;
    if (kd) {
        st = bvh_build_top_level(in, protos, n_protos, out->instances, objects, out->n_instances, &motion, threads,
                                 &out->bvh, &out->levels, err);
        if (!st)
            st = kd_build_prototypes(in, protos, n_protos, out->instances, objects, out->n_instances, threads,
                                     &out->kd, &out->kd_protos, &out->kd_levels, err);
    } else {
        st = bvh_build_instanced(in, protos, n_protos, out->instances, objects, out->n_instances, &motion, threads,
                                 &out->bvh, &out->levels, err);
    }
    if (st == ST_INPUT && out->levels.inst_beyond < s->n_instances) {
        /* named as the file wrote it (the world's own shapes, within 2^62 since they
         * were read, never reach this far: bvh_inst.c's message stays for them) */
        uint i = out->levels.inst_beyond;
        const char *name = s->objects[objects[i]].name;
        if (isinf(out->levels.inst_beyond_at))
            st = error_set(err, ST_INPUT, "instance %u (of object '%s'): its world box does not fit in floats", i, name);
        else
            st = error_set(err, ST_INPUT, "instance %u (of object '%s'): its world box reaches %g, beyond the %g (2^110) "
                           "instanced scenes hold", i, name, (double)out->levels.inst_beyond_at,
                           (double)BVH_TOP_COORD_MAX);
    }
    if (st) goto done;
    out->instanced = 1;
    if (kd) {
        /* the kd-trees' nodes and leaves (no root box of their own: each is in its
         * record), then the top level, whose box is the world's */
        render_scene_use_kdtree(&out->ds, &out->kd);
        out->n_kd_protos = n_protos;
        out->ds.kd_protos = out->kd_protos;
        out->ds.n_kd_protos = (uint)n_protos;
    }
    render_scene_use_bvh(&out->ds, &out->bvh);
    out->ds.params.bounds_lo = out->bvh.lo;
    out->ds.params.bounds_hi = out->bvh.hi;
    out->ds.params.n_instances = (uint)out->n_instances;
    out->ds.instances = out->instances;
done:
    free(objects);
    free(protos);
    free(obj_ranges);
    free(world);
    return st;
}

/* The scene's tree into out, and out->ds pointed at it. */
static Status tree_build(const Scene *s, int threads, RenderScene *out, Error *err)
{
    KdInput in = { s->spheres, s->n_spheres, s->triangles, s->n_triangles, s->boxes, s->n_boxes,
                   s->revsurfaces, s->n_revsurfaces, s->sphere_xforms, s->n_sphere_xforms, NULL, 0 };
    Status st;
    if (s->n_objects) return tree_build_instanced(s, &in, threads, out, err);
    if (s->accel == ACCEL_KDTREE) {
        if ((st = kd_build(&in, threads, &out->kd, err))) return st;
        render_scene_use_kdtree(&out->ds, &out->kd);
        return ST_OK;
    }
    if ((st = bvh_build(&in, threads, &out->bvh, err))) return st;
    render_scene_use_bvh(&out->ds, &out->bvh);
    return ST_OK;
}

/* The film's size and where it lies in the image: the crop's window, the whole image
 * without one. The camera spans the whole image either way. */
static Status crop_params(const Scene *s, RenderParams *p, Error *err)
{
    CropWindow w;
    if (!crop_window(&s->crop, s->image.width, s->image.height, &w))
        return error_set(err, ST_INPUT, s->crop.kind == CROP_PIXELS ? "%s: the pixel bounds %g,%g,%g,%g go past the "
                                                                      "%ux%u image"
                                                                    : "%s: the crop window %g,%g,%g,%g selects no "
                                                                      "pixel of the %ux%u image",
                         s->path ? s->path : "scene", s->crop.x0, s->crop.x1, s->crop.y0, s->crop.y1,
                         s->image.width, s->image.height);
    p->width = w.width;
    p->height = w.height;
    p->crop_left = w.x0;
    p->crop_top = w.y0;
    p->crop_right = s->image.width - w.x0 - w.width;
    p->crop_bottom = s->image.height - w.y0 - w.height;
    return ST_OK;
}

/* The media's part of the device scene (kernels/medium/). First-hit splitting
 * restarts a path at the camera ray's first hit, which a camera inside a medium may
 * never reach (the flight toward it may scatter first): there the two are not
 * combined. */
static Status prepare_media(const Scene *s, RenderScene *out, Error *err)
{
    RenderParams *p = &out->ds.params;
    p->has_media = scene_has_media(s) ? HAS_MEDIA_ANY | (scene_has_subsurface(s) ? HAS_MEDIA_WALK : 0u) : 0u;
    p->n_media = (uint)s->n_media;
    p->camera_medium = scene_medium_resolve(s, s->camera_medium);
    out->ds.media = s->n_media ? s->media : NULL;
    p->n_grids = (uint)s->n_grids;
    out->ds.grids = s->n_grids ? s->grids : NULL;
    out->ds.grid_data = s->n_grid_data ? s->grid_data : NULL;
    out->ds.n_grid_data = s->n_grid_data;
    if (p->camera_medium != 0u && p->split > 1u)
        return error_set(err, ST_USAGE, "first-hit splitting (--split %u) does not work with the camera inside a "
                         "participating medium; render it with --split 1", p->split);
    return ST_OK;
}

/* The moving parts (docs/motion.md): the camera (prepared here, in its own space when
 * it moves) and the instances; their keys in one device buffer, the instances' first
 * (their indices are the scene's), then the camera's. */
static Status prepare_motion(const Scene *s, RenderScene *out, Error *err)
{
    RenderParams *p = &out->ds.params;
    MotionKey *camera_keys = NULL;
    Status st = camera_setup_moving(s, s->image.width, s->image.height, (uint)s->n_motion_keys, &p->camera,
                                    &camera_keys, err);
    if (st) return st;
    size_t n = s->n_motion_keys + p->camera.motion_keys;
    p->camera.moving = n != 0;
    if (n == 0) return ST_OK;
    if (!(out->motion_keys = malloc(n * sizeof *out->motion_keys))) {
        free(camera_keys);
        return error_set(err, ST_INTERNAL, "out of memory for %zu motion keys", n);
    }
    if (s->n_motion_keys) memcpy(out->motion_keys, s->motion_keys, s->n_motion_keys * sizeof *out->motion_keys);
    if (camera_keys) {
        for (uint i = 0; i < p->camera.motion_keys; i++) camera_keys[i].count = p->camera.motion_keys;
        memcpy(out->motion_keys + s->n_motion_keys, camera_keys, p->camera.motion_keys * sizeof *camera_keys);
    }
    free(camera_keys);
    out->ds.motion_keys = out->motion_keys;
    out->ds.n_motion_keys = (uint)n;
    return ST_OK;
}

static Status prepare(Scene *s, int tree_threads, RenderScene *out, Error *err)
{
    Status st;
    /* the path tracer samples a cube map as an environment light; Whitted keeps the
     * course's exact lookup (cube_env.h) */
    if (s->integrator == INTEGRATOR_PATH && s->bg_type == BG_CUBEMAP && (st = cube_env_convert(s, err))) return st;
    /* the media first: a bound material's copy may emit (scene/media.h) */
    scene_prepare_media(s);
    if ((st = scene_prepare_lights(s, err))) return st;
    /* after everything that reads float texels on the host (the map's distribution, the
     * cube map's conversion) */
    if ((st = scene_pack_texels(s, err))) return st;
    RenderParams *p = &out->ds.params;
    if ((st = prepare_motion(s, out, err))) return st;
    if ((st = scene_check_precision(s, err))) return st;
    if ((st = tree_build(s, tree_threads, out, err))) return st;
    p->bg_type = s->bg_type;
    p->bg_color = s->bg_color;
    p->bg_zenith = s->bg_zenith;
    p->bg_cubemap = s->bg_cubemap;
    double rot = fmod((double)s->bg_rotate, 360.0) * (M_PI / 180.0);
    p->bg_rot_cos = (float)cos(rot);
    p->bg_rot_sin = (float)sin(rot);
    p->bg_light = s->env_light;
    p->env_mis_dist = (uint)s->env_mis_dist;   /* env_dist_build keeps it below 2^32 */
    if ((st = crop_params(s, p, err))) return st;
    p->max_depth = s->image.max_depth;
    p->split = s->image.split;   /* 0: auto, chosen by render_job_run's pilot (split_pilot.h); 1 until then */
    p->clamp_indirect = s->image.clamp_indirect;
    if ((st = prepare_media(s, out, err))) return st;
    p->rr_depth = RR_START_BOUNCE;
    p->seed = s->image.seed;
    p->sampler = s->image.sampler;
    p->n_spheres = (uint)s->n_spheres;
    p->n_triangles = (uint)s->n_triangles;
    p->n_boxes = (uint)s->n_boxes;
    p->n_planes = (uint)s->n_planes;
    p->n_revsurfaces = (uint)s->n_revsurfaces;
    p->n_lights = (uint)s->n_lights;
    out->ds.spheres = s->spheres;
    out->ds.sphere_xforms = s->n_sphere_xforms ? s->sphere_xforms : NULL;
    out->ds.n_sphere_xforms = (uint)s->n_sphere_xforms;
    out->ds.triangles = s->triangles;
    out->ds.instance_lights = s->instance_lights;
    out->ds.n_instance_lights = s->instance_lights ? (uint)s->n_instances : 0u;
    out->ds.boxes = s->boxes;
    out->ds.planes = s->planes;
    out->ds.revsurfaces = s->revsurfaces;
    out->ds.rev_points = s->rev_points;
    out->ds.n_rev_points = s->n_rev_points;
    out->ds.materials = s->materials;
    out->ds.n_materials = (uint)s->n_materials;
    p->has_alpha = 0u;
    for (size_t i = 0; i < s->n_materials; i++)
        if (s->materials[i].flags & MAT_ALPHA_ANY) p->has_alpha = 1u;
    out->ds.lights = s->lights;
    out->ds.shading = s->shading;
    out->ds.n_shading = (uint)s->n_shading;
    out->ds.tri_extra_of = s->n_tri_extras ? s->tri_extra_of : NULL;
    out->ds.n_tri_extra_of = s->n_tri_extras ? (uint)s->n_shading : 0u;
    out->ds.tri_extras = s->tri_extras;
    out->ds.n_tri_extras = (uint)s->n_tri_extras;

    /* the classic ray tracer's part (kernels/integrator/whitted.h) */
    p->ambient = s->ambient;
    p->integrator = s->integrator;
    p->mis_mode = MIS_BOTH;
    p->n_area_lights = (uint)(s->n_lights - s->n_delta_lights - (s->env_light != NO_INDEX ? 1u : 0u));
    p->n_textures = (uint)s->n_textures;
    p->pixel_list_size = 0;
    /* only the whitted camera (whitted and the auxiliary images) reads the grid; the
     * path tracer's samples must not depend on the samples per pixel, or a render could
     * not grow (render key, checkpoint.c) */
    p->strata = s->integrator != INTEGRATOR_PATH ? render_scene_strata(s->image.spp) : 0u;
    p->sample_offset = 0;
    p->normal_miss_grey = s->normal_miss_grey;
    p->shadows = s->shadows ? 1u : 0u;
    out->ds.textures = s->textures;
    out->ds.texels = s->texels;
    out->ds.n_texels = s->n_texels;
    out->ds.env_cdf = s->env_cdf;
    out->ds.n_env_cdf = s->n_env_cdf;
    out->ds.pixel_list = NULL;
    return ST_OK;
}

/* What a failed preparation had made is freed here: the caller has nothing to free
 * (a refused instance box left the instance records behind, found by LeakSanitizer). */
Status render_scene_prepare(Scene *s, int tree_threads, RenderScene *out, Error *err)
{
    memset(out, 0, sizeof *out);
    Status st = prepare(s, tree_threads, out, err);
    if (st != ST_OK) render_scene_free(out);
    return st;
}

uint render_scene_list_pixels(const uint *mask, size_t n, uint *list)
{
    uint listed = 0;
    for (size_t i = 0; i < n; i++)
        if (mask[i]) list[listed++] = (uint)i;
    return listed;
}

void render_scene_free(RenderScene *r)
{
    free(r->instances);
    free(r->motion_keys);
    free(r->instance_motion);
    free(r->kd_protos);
    kd_free(&r->kd);
    bvh_free(&r->bvh);
    memset(r, 0, sizeof *r);
}
