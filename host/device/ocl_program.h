/*
 * ocl_program.h — builds clpt's OpenCL program for one device, with an on-disk cache
 * of compiled binaries.
 *
 * The kernel source is embedded in the binary at build time (tools/embed.c flattens
 * kernels/entry.cl and its includes into build/kernel_source.c), so a normal run needs
 * no kernel files. A developer can point at a kernel folder instead (--kernel-dir),
 * which reads <dir>/entry.cl and compiles it with -I <dir>; that mode is never cached,
 * because the included files are not part of the cache key.
 *
 * Build options are always "-cl-std=CL1.2", plus "-cl-fp32-correctly-rounded-divide-sqrt"
 * when the device supports it (the scalar C device computes IEEE-rounded / and sqrt, and
 * the two must give the same bits), plus the caller's extra options (the device passes
 * -D CLPT_FEATURES=..., which selects the kernels and the code compiled: types.h). Never
 * -cl-fast-relaxed-math or -cl-mad-enable, for the same reason.
 *
 * The cache: one file per (source, device, driver, options), named by the SHA-256 of all
 * of them, in $CLPT_CACHE_DIR, else $XDG_CACHE_HOME/clpt, else $HOME/.cache/clpt. A file
 * holds a magic, the key, the payload length and the payload's SHA-256, then the
 * device's CL_PROGRAM_BINARIES. Files are written to a temporary name in the same folder
 * and renamed, so a concurrent run sees either no file or a whole one. Anything wrong
 * with an entry (truncated, corrupt, refused by the driver, or a program that did not
 * build for the device or holds no kernel) deletes it and the program is rebuilt
 * from source and stored again; so is an entry that is not a regular file (a FIFO or
 * a folder: opened without blocking). A payload with a right checksum can still crash
 * the driver, so a new entry is first loaded in a trial process (ocl_program.c, "the
 * trial load"): a crash there costs nothing but a compile from source, past whatever
 * the driver kept of it. A cache folder that cannot be created only means building from
 * source, and one that cannot be written (a farm's read-only copy) is read but not
 * written: it never fails a run. Runs that share the folder, on one machine or many
 * (docs/design.md, "A cache for a farm"), all load an entry while one of them reads it.
 *
 * Storing an entry reads CL_PROGRAM_BINARIES right after the build, which makes PoCL 3.1
 * compile every kernel of the program (a work-group function for any local size) on top
 * of the compile of each kernel at its first launch. That is why the device keeps its
 * programs small (device_ocl.c). Doing the read-back in a thread of its own while the
 * render starts gains nothing there: PoCL compiles one kernel at a time per process
 * (bench/RESULTS.md, start-up).
 */
#ifndef CLPT_OCL_PROGRAM_H
#define CLPT_OCL_PROGRAM_H

#include "device/kernel_source.h"
#include "device/ocl.h"

typedef struct {
    double seconds;        /* wall time of the whole ocl_program_build call */
    int from_cache;        /* 1 when the program came from the on-disk cache */
    char options[512];     /* the build options used (truncated if ever longer) */
    char cache_path[1024]; /* the cache entry for this build; "" when not cached */
} OclProgramStats;

/* Builds the program for `dev`, which must belong to `ctx`. kernel_dir NULL uses the
 * embedded source; extra_options may be NULL. On success *out is a built program the
 * caller releases; stats may be NULL. A failed build is ST_DEVICE naming the device,
 * clBuildProgram, the error and the options, with the whole build log in err->detail;
 * an unreadable kernel folder is ST_IO. */
Status ocl_program_build(cl_context ctx, const OclDeviceInfo *dev, const char *kernel_dir,
                         const char *extra_options, cl_program *out, OclProgramStats *stats,
                         Error *err);

/* ocl_program_build for another program than the renderer's: src (e.g. the traversal
 * benchmark's clpt_bench_kernel_source) with the same options and cache. */
Status ocl_program_build_source(cl_context ctx, const OclDeviceInfo *dev, const char *src,
                                size_t src_len, const char *extra_options, cl_program *out,
                                OclProgramStats *stats, Error *err);

/* Whether a build from source (a cache miss, or --kernel-dir) first says so on stderr:
 * "clpt: compiling kernels for <device>, cached for next time..." (without ", cached
 * for next time" when nothing is cached: --kernel-dir, or no cache folder). Off until
 * turned on (the program does, unless -q). */
void ocl_program_announce_builds(int on);

/* clCreateKernel, failing with the device and kernel name in the message. */
Status ocl_program_kernel(cl_program prog, const OclDeviceInfo *dev, const char *name,
                          cl_kernel *out, Error *err);

/* Writes the cache folder the environment selects (not created here) into buf; returns 0
 * when there is none (no variable set) or it does not fit. */
int ocl_program_cache_dir(char *buf, size_t cap);

#endif /* CLPT_OCL_PROGRAM_H */
