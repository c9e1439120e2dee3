/*
 * kernel_features.h — which kernel code a scene needs (the KF_* switches of
 * kernels/types.h), and whether its paths can run eight at a time (k_path_lanes). The
 * OpenCL device builds its programs from these answers; test_kernels checks them on
 * its scenes.
 */
#ifndef CLPT_KERNEL_FEATURES_H
#define CLPT_KERNEL_FEATURES_H

#include "device/device.h"

/* The features the background of params needs. */
unsigned kernel_params_features(const RenderParams *p);

/* The features the scene needs besides the integrator's kernels: every switch whose
 * code the scene can reach, and no other. */
unsigned kernel_scene_features(const DeviceScene *s);

/* Whether k_path_lanes can render the scene (features: kernel_scene_features's):
 * every surface a flat triangle of an untextured diffuse material that does not emit,
 * or a lamp (a pure emitter), every light a triangle lamp. In such a scene a path that
 * shade_lanes does not shade in float8 ends where it is (kernels/integrator/shade_lanes.h). */
int kernel_lanes_scene(const DeviceScene *s, unsigned features);

/* ... and whether the render settings allow it too: the Sobol sampler, MIS and shadows,
 * which the float8 shading assumes, and no --clamp, which it does not apply. */
int kernel_lanes_params(const RenderParams *p);

#endif /* CLPT_KERNEL_FEATURES_H */
