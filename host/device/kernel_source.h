/*
 * kernel_source.h — the kernel source embedded at build time (tools/embed.c flattens
 * kernels/entry.cl and its includes into build/kernel_source.c, and kernels/bench/trace.cl
 * into build/bench_kernel_source.c): what the OpenCL devices
 * compile, and what the checkpoint render key hashes. Plain C, no OpenCL types.
 */
#ifndef CLPT_KERNEL_SOURCE_H
#define CLPT_KERNEL_SOURCE_H

#include <stddef.h>

extern const char clpt_kernel_source[];
extern const size_t clpt_kernel_source_len;

/* The traversal benchmark's program (kernels/bench/trace.cl): linked only into the
 * programs that use it (bench_traverse, test_kernels). */
extern const char clpt_bench_kernel_source[];
extern const size_t clpt_bench_kernel_source_len;

#endif /* CLPT_KERNEL_SOURCE_H */
