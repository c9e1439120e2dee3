/*
 * mesh_view.h — a scene made around a bare mesh file, so that `clpt model.ply` shows it.
 *
 * The mesh keeps its MTL materials when it has them, else it is neutral grey diffuse
 * (MESH_DEFAULT_ALBEDO). It is lit by a sky background and a sun: a small emissive
 * sphere far away (2.5 degrees across, up and to the front left of the mesh), which the
 * renderer samples as it samples any light. The camera looks at the centre of the mesh's
 * bounding box from the front (+z), a little above and to the right, far enough that the
 * bounding sphere fits the view. docs/meshes.md gives the numbers.
 */
#ifndef CLPT_MESH_VIEW_H
#define CLPT_MESH_VIEW_H

#include "scene/scene.h"

/* Loads the mesh (an .obj or .ply file) into an initialised scene and adds the sky, the
 * sun and a camera for the scene's image size. ST_INPUT when it has no triangle. */
Status mesh_view_load(const char *path, Scene *s, Error *err);
/* The same around the triangles already in the scene, read from the mesh `path`. */
Status mesh_view_frame(const char *path, Scene *s, Error *err);

/* Points the camera at the mesh again for the scene's current image size (call after
 * changing width or height: a tall image needs the camera farther back). ST_INPUT,
 * naming the mesh file, when the camera would be beyond the float range (a mesh whose
 * corners are near it). */
Status mesh_view_fit(Scene *s, Error *err);

#endif /* CLPT_MESH_VIEW_H */
