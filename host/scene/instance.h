/*
 * instance.h — objects and their instances in a scene (docs/instancing.md).
 *
 * An object is a set of primitives made between scene_object_begin and
 * scene_object_end; an instance places it in the world under an affine transform, with
 * an optional material that replaces its primitives'. The primitives stay once in the
 * scene's arrays however many instances there are: the BVH walks them in the object's
 * space under either tree (host/accel/bvh_inst.c, kd_inst.c). scene_flatten_instances
 * makes copies instead, for the classic reader's meshes placed once and for the tests
 * that compare the two.
 */
#ifndef CLPT_SCENE_INSTANCE_H
#define CLPT_SCENE_INSTANCE_H

#include <stdint.h>

#include "scene/scene.h"

/* The most instances a scene holds: every one costs a device record (Instance, 108
 * bytes) and a top-level leaf, and the top level's node indices must fit the walk's. */
#ifndef CLPT_FUZZ_BUILD
#define SCENE_MAX_INSTANCES (1u << 24)
#else
/* `make fuzz` (CLPT_FUZZ_BUILD): a few nested objects in a 3 KB file reach 2^24
 * instances, 1.8 GB of records, over libFuzzer's 1 GB for one input; the fuzz build
 * checks the same code against 2^16. */
#define SCENE_MAX_INSTANCES (1u << 16)
#endif
/* The most objects a scene defines. */
#define SCENE_MAX_OBJECTS (1u << 20)
/* The deepest chain of objects that hold instances of objects (an object of shapes
 * alone is 1 deep): nesting is resolved at load, and each level can multiply the
 * instances, so the depth is bounded as the count is (docs/instancing.md). */
#define SCENE_MAX_NESTING 8u

/* Starts object `name` (len bytes; must not be defined yet: scene_find_object) at the
 * scene's current primitive counts; *index receives it. Fails when memory runs out
 * (ST_INTERNAL) or past SCENE_MAX_OBJECTS (ST_INPUT, no location). */
Status scene_object_begin(Scene *s, const char *name, size_t len, uint *index, Error *err);
/* The same for an object whose primitives were made already: those added since the
 * scene held `first` of each kind (scene_object_counts, read when they began). Readers
 * that learn only at its end whether a block becomes an object (pbrt's ObjectEnd) use
 * it; no other object may have begun since. */
Status scene_object_begin_from(Scene *s, const char *name, size_t len, const size_t first[OBJ_KINDS], uint *index,
                               Error *err);
/* The scene's current count of each kind of primitive. */
void scene_object_counts(const Scene *s, size_t n[OBJ_KINDS]);
/* Ends object `index`: the primitives added since its start are its own. */
void scene_object_end(Scene *s, uint index);
/* The object named so, or NO_INDEX. */
uint scene_find_object(const Scene *s, const char *name, size_t len);
/* Primitives of object `index`, of every kind. */
size_t scene_object_prims(const Scene *s, uint index);

/* An instance of object `object` under m, its primitives of `material` (NO_INDEX: their
 * own). ST_INPUT (message without a location) when m is singular, it or its inverse
 * does not fit in floats, or past SCENE_MAX_INSTANCES; ST_INTERNAL without memory. */
Status scene_add_instance(Scene *s, uint object, const Transform *m, uint material, Error *err);

/* An instance of `object` inside the block of `holder` (the object being read, begun
 * last and not ended), under m in the holder's space, its primitives of `material`
 * (NO_INDEX: their own). ST_INPUT (message without a location) when object is the
 * holder, when the chain of objects would be more than SCENE_MAX_NESTING deep, or m is
 * singular; ST_INTERNAL without memory. */
Status scene_object_nest(Scene *s, uint holder, uint object, const Transform *m, uint material, Error *err);
/* Places `object` in the world under m (scene_add_instance's arguments): one instance
 * for its own primitives (when it has any), then each instance its block holds, under
 * m times that instance's transform (composed in double), depth first in the order
 * written. The outermost material given replaces all the others below it. The count
 * is checked against SCENE_MAX_INSTANCES before anything is allocated (ST_INPUT,
 * message without a location, naming the count); otherwise as scene_add_instance. */
Status scene_place_object(Scene *s, uint object, const Transform *m, uint material, Error *err);

/* Global primitive ids by kind: the ranges of object `index`, in increasing order
 * (empty kinds left out); returns how many (at most OBJ_KINDS). */
size_t scene_object_ranges(const Scene *s, uint index, uint lo[OBJ_KINDS], uint hi[OBJ_KINDS]);
/* The world's own primitives (those in no object): *mask gets one byte per global id
 * before the planes, 1 for a primitive of an object (NULL, and 0 returned, when the
 * scene has no objects). ST_INTERNAL without memory. */
Status scene_object_mask(const Scene *s, uint8_t **mask, Error *err);

/* Replaces every instance by copies of its object's primitives carried to the world
 * (corners and normals transformed in double, spheres as ellipsoids, boxes under a
 * diagonal linear part as boxes), then drops the objects' own primitives and the
 * objects: the scene is then one without instances. An identity instance copies the
 * primitives bit for bit. ST_INPUT (no location) for what has no copy in the world's
 * kinds: a box under a rotation, a surface of revolution under any transform but the
 * identity; the scene is unchanged then. ST_INTERNAL without memory. The renderer keeps
 * instances under both trees (docs/instancing.md); the tests compare against the copies. */
Status scene_flatten_instances(Scene *s, Error *err);

/* Frees the objects and instances (scene_free calls it). */
void scene_free_objects(Scene *s);

#endif /* CLPT_SCENE_INSTANCE_H */
