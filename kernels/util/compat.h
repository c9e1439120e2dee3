/*
 * compat.h — lets every file under kernels/ compile both as OpenCL C 1.2 and as C11.
 *
 * The kernel stage functions are written once. OpenCL compilers see them through
 * entry.cl; the scalar C device (host/device/device_scalar.c) and the tests #include the very
 * same files. This header is the only place where the two languages differ.
 *
 * Rules for kernel code (so that both compilers produce the same bits):
 *  - float literals always carry the f suffix (no silent double promotion in C);
 *  - only + - * / and sqrt are used on floats, plus the k_* functions of kmath.h that
 *    are built from them; no libm / OpenCL builtins with implementation-defined
 *    precision (sin, exp, pow ...), because PoCL, NVIDIA and glibc round them
 *    differently and the image would then depend on the device;
 *  - contraction into fused multiply-add is disabled on both sides (the pragma below
 *    and -ffp-contract=off in the Makefile); the host asks OpenCL for correctly
 *    rounded divide and sqrt where the device supports it.
 */
#ifndef CLPT_COMPAT_H
#define CLPT_COMPAT_H

/* Keyed on __OPENCL_C_VERSION__, which every OpenCL C 1.2 compiler defines (the
 * language version), online or offline (clang -cl-std=CL1.2, ocloc ...);
 * __OPENCL_VERSION__ names the device's OpenCL version and is only promised when
 * compiling for a device. The other kernel files test KERNEL_OPENCL. */
#if defined(__OPENCL_C_VERSION__)
/* ---------------------------------------------------------------- OpenCL C */
#pragma OPENCL FP_CONTRACT OFF

#define KERNEL_OPENCL 1
#define KFN static inline       /* every helper: never bare `inline` (C99 rules) */
/* Hot helpers that must be inlined whatever the compiler's size heuristics say: a call
 * forces their state through memory (PoCL kept the kd-tree walk's state in memory). */
#define KFN_INLINE static inline __attribute__((always_inline))
/* Helpers that OpenCL compilers must inline and C compilers may leave out of line.
 * PoCL's inliner left k_atan2 and rng_uniform calls (cost 330 and 260 against its
 * threshold of 225); inlined, PoCL renders the envmap scene 13% faster, one-weekend 4%,
 * the McGuire box 2%. gcc inlining k_atan2 into the shading made the scalar device 10%
 * slower on the envmap scene, so C keeps its own choice. */
#define KFN_INLINE_CL static inline __attribute__((always_inline))
/* Large stage functions that CPUs' OpenCL compilers (PoCL) must keep as calls: PoCL
 * compiles a kernel's body three times (the kernel and two work-group functions), so
 * inlined into k_path, shade_path took it 2.3 s to build mesh.scene's program instead of
 * 1.6 s (bench/RESULTS.md). GPU compilers, for which a call costs more, and C compilers
 * choose for themselves. */
#if defined(__x86_64__) || defined(__aarch64__)
#define KFN_CALL_CL static inline __attribute__((noinline))
#else
#define KFN_CALL_CL static inline
#endif
#define GLOBAL __global
#define CONSTANT __constant

#define k_sqrt(x) sqrt(x)
#define k_fabs(x) fabs(x)
#define k_floor(x) floor(x)
#define k_as_float(u) as_float(u)
#define k_as_uint(f) as_uint(f)
#define k_as_int(f) as_int(f)
#define k_int_as_float(i) as_float(i)

typedef long kint64;         /* 64-bit in every OpenCL C implementation */

#define k_load4(v, p) ((v) = vload4(0, p))
#define k_load8(v, p) ((v) = vload8(0, p))
#define k_store4(v, p) vstore4(v, 0, p)
#define k_store8(v, p) vstore8(v, 0, p)
/* per lane: b where the mask m's lane is set (-1), else a */
#define k_select8(a, b, m) select(a, b, m)
#define k_splat8(x) ((float8)(x))
/* 8 lanes run as one vector (float8): in OpenCL always */
#define K_VEC8 1
/* A comparison's 8 lanes (-1 or 0 each) as bits, lane i at 1 << i, and whether any is
 * set. On x86 CPUs with AVX (PoCL) one vmovmskps: LLVM compiles the lane-by-lane form
 * below into a tree of shuffles and ORs, and these reductions sit in every node and
 * triangle-group test (the peers' Cornell box and dragon rendered 7-8% faster with the
 * instruction). The same bits either way. */
#if defined(__x86_64__) && defined(__AVX__)
#define k_bits8(m) ((uint)__builtin_ia32_movmskps256(as_float8(m)))
#define k_any8(m) (k_bits8(m) != 0u)
#endif

#elif defined(__OPENCL_VERSION__)
#error "an OpenCL compiler without __OPENCL_C_VERSION__: clpt's kernels need OpenCL C 1.2 (-cl-std=CL1.2)"
#else
/* ---------------------------------------------------------------- C11 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#define KFN static inline
#define KFN_INLINE static inline __attribute__((always_inline))
#define KFN_INLINE_CL static inline
#define KFN_CALL_CL static inline
#define GLOBAL
#define CONSTANT const

typedef unsigned int uint;   /* same as glibc's <sys/types.h> typedef */
typedef unsigned char uchar;
typedef int64_t kint64;

#define k_sqrt(x) sqrtf(x)
#define k_fabs(x) fabsf(x)
#define k_floor(x) floorf(x)

static inline float k_as_float(uint u) { float f; memcpy(&f, &u, sizeof f); return f; }
static inline uint k_as_uint(float f) { uint u; memcpy(&u, &f, sizeof u); return u; }
static inline int k_as_int(float f) { int i; memcpy(&i, &f, sizeof i); return i; }
static inline float k_int_as_float(int i) { float f; memcpy(&f, &i, sizeof f); return f; }

/* OpenCL's 4-wide vectors as GCC vector extensions, which compute each lane with the
 * same IEEE operation as OpenCL does. Kernel code uses only operators (with vector or
 * scalar operands), comparisons (-1 or 0 per lane, as OpenCL's), lane subscripts,
 * k_load4 (v = the 4 floats at p) and k_store4 on them. Kernels that use 8 lanes on
 * OpenCL (float8, k_load8, k_store8) run them as two halves of 4 in C unless it is
 * compiled with AVX (K_VEC8 below): without AVX gcc splits 8-wide vectors badly
 * (intersect.h). */
typedef float float4 __attribute__((vector_size(16)));
typedef int int4 __attribute__((vector_size(16)));
#define k_load4(v, p) memcpy(&(v), (p), sizeof(float4))
#define k_store4(v, p) memcpy((p), &(v), sizeof(float4))
/* The four bytes of w, the low one first, as the lanes of an int4 (the compressed
 * top level's step counts, traverse_bvh.h): on x86 two unpacks with zero (SSE2, in
 * every x86-64), where gcc makes eleven scalar instructions of the lane-by-lane form
 * and of __builtin_convertvector. */
#if defined(__SSE2__)
#include <emmintrin.h>
static inline int4 k_bytes4(uint w)
{
    __m128i zero = _mm_setzero_si128();
    return (int4)_mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128((int)w), zero), zero);
}
#else
static inline int4 k_bytes4(uint w)
{
    return (int4){ (int)(w & 0xffu), (int)((w >> 8) & 0xffu), (int)((w >> 16) & 0xffu), (int)(w >> 24) };
}
#endif
/* 8 lanes: the packet walk's (traverse.h; in C its reference, not a fast path), and
 * with AVX the node and triangle-group tests' */
typedef float float8 __attribute__((vector_size(32)));
typedef int int8 __attribute__((vector_size(32)));
#define k_load8(v, p) memcpy(&(v), (p), sizeof(float8))
#define k_store8(v, p) memcpy((p), &(v), sizeof(float8))
/* a vector cast keeps the bits (GCC's vector extension) */
#define k_select8(a, b, m) ((float8)(((int8)(a) & ~(m)) | ((int8)(b) & (m))))
#define k_splat8(x) ((float8){ (x), (x), (x), (x), (x), (x), (x), (x) })
/* Whether the hot 8-lane tests (a BVH node's boxes, a group of triangles) run as one
 * float8 (K_VEC8 1) or as two float4 halves: with AVX (the scalar device's -mavx2
 * builds) one register holds the 8 lanes; without it gcc splits 8-wide vectors badly. */
#if defined(__AVX__)
#define K_VEC8 1
#define k_bits8(m) ((uint)__builtin_ia32_movmskps256((float8)(m)))
#define k_any8(m) (k_bits8(m) != 0u)
#else
#define K_VEC8 0
#endif
/* A comparison's 4 lanes as bits (as k_bits8 above): one movmskps on x86 (SSE, in every
 * x86-64), which gcc does not find in the lane-by-lane form. */
#if defined(__SSE__)
#define k_bits4(m) ((uint)__builtin_ia32_movmskps((float4)(m)))
#define k_any4(m) (k_bits4(m) != 0u)
#endif

#endif

/* The lane-by-lane reductions, where no instruction does it (GPUs, other CPUs): the
 * lanes written out, since compilers make slower code of a loop over them. */
#ifndef k_bits8
#define k_any8(m) (((m)[0] | (m)[1] | (m)[2] | (m)[3] | (m)[4] | (m)[5] | (m)[6] | (m)[7]) != 0)
#define k_bits8(m)                                                                       \
    ((uint)((m)[0] & 1) | (uint)((m)[1] & 2) | (uint)((m)[2] & 4) | (uint)((m)[3] & 8) |    \
     (uint)((m)[4] & 16) | (uint)((m)[5] & 32) | (uint)((m)[6] & 64) | (uint)((m)[7] & 128))
#endif
#ifndef k_bits4
#define k_any4(m) (((m)[0] | (m)[1] | (m)[2] | (m)[3]) != 0)
#define k_bits4(m) ((uint)((m)[0] & 1) | (uint)((m)[1] & 2) | (uint)((m)[2] & 4) | (uint)((m)[3] & 8))
#endif

/* The index of the lowest set bit of m != 0, and of the highest. OpenCL C 1.2 has clz
 * but no ctz; on x86 CPUs (PoCL, whose compiler is clang) the builtin is one tzcnt where
 * the clz form took three dependent instructions, in the chain from a BVH node's test to
 * the next node's loads. */
#if defined(KERNEL_OPENCL) && defined(__x86_64__)
#define k_lowest_bit(m) ((uint)__builtin_ctz(m))
#define k_highest_bit(m) (31u - clz(m))
#elif defined(KERNEL_OPENCL)
#define k_lowest_bit(m) (31u - clz((m) & (0u - (m))))
#define k_highest_bit(m) (31u - clz(m))
#else
#define k_lowest_bit(m) ((uint)__builtin_ctz(m))
#define k_highest_bit(m) (31u - (uint)__builtin_clz(m))
#endif

/* fmin/fmax with IEEE semantics (a NaN argument loses), written out the same way for
 * both compilers: gcc cannot inline fminf without fast-math and calls libm for every
 * use, which cost the scalar device about a tenth of its time in traversal; and a
 * shared definition settles fmin(-0, +0), which the standards leave open. */
static inline float k_fmin(float a, float b) { return (b < a || a != a) ? b : a; }
static inline float k_fmax(float a, float b) { return (b > a || a != a) ? b : a; }

#endif /* CLPT_COMPAT_H */
