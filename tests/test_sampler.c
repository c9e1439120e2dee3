/*
 * test_sampler.c — the Sobol sampler of kernels/sample/rng.h: the unscrambled sequence is
 * Sobol's (its first points, and every point against the direction-number definition),
 * values lie in [0, 1), every 2D pair of dimensions is a (0,2)-sequence after scrambling
 * and shuffling (each elementary interval holds one point of every aligned block of
 * 2^m samples) and every 1D dimension is stratified, pixels and pairs are decorrelated,
 * and OpenCL (PoCL) computes the same bits as C for both samplers. Whole images: the
 * independent sampler's too are the same bits on PoCL and scalar (the image tests of
 * test_render and test_checkpoint run the default, Sobol), and Sobol's error at equal
 * samples is lower.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "device/ocl_program.h"
#include "io/scene_load.h"
#include "render_util.h"
#include "sample/rng.h"

/* Sobol dimension 1 by its definition: the XOR of direction numbers v_k = m_k / 2^(k+1)
 * over the set bits k of the index. Joe and Kuo's table (new-joe-kuo-6.21201) gives
 * this dimension s = 1, a = 0, m_1 = 1, so m_k = 2 m_(k-1) XOR m_(k-1): 1, 3, 5, 15,
 * 17, 51, 85, 255, ... (the rows of Pascal's triangle mod 2), checked here as listed. */
static uint sobol1_by_directions(uint index)
{
    uint v[32], x = 0;
    uint m = 1;
    for (int k = 0; k < 32; k++) {
        if (k > 0) m = (m << 1) ^ m;
        v[k] = m << (31 - k);
    }
    for (int k = 0; k < 32; k++)
        if (index >> k & 1u) x ^= v[k];
    return x;
}

static void test_first_points(void)
{
    /* the first eight points of the 2D Sobol sequence, in index (not Gray-code) order */
    static const double want[8][2] = { { 0, 0 },         { 0.5, 0.5 },     { 0.25, 0.75 },   { 0.75, 0.25 },
                                       { 0.125, 0.625 }, { 0.625, 0.125 }, { 0.375, 0.375 }, { 0.875, 0.875 } };
    for (uint i = 0; i < 8; i++)
        for (uint d = 0; d < 2; d++)
            CHECK_MSG(rng_sobol(i, d) == (uint)(want[i][d] * 4294967296.0), "point %u dim %u: %08x", i, d,
                      rng_sobol(i, d));
    static const uint m_listed[8] = { 1, 3, 5, 15, 17, 51, 85, 255 };
    for (uint k = 0; k < 8; k++) CHECK_EQ_INT(sobol1_by_directions(1u << k), m_listed[k] << (31 - k));
    uint bad = 0;
    for (uint i = 0; i < 1u << 16; i++) bad += rng_sobol(i, 1) != sobol1_by_directions(i);
    for (uint i = 0, x = 12345u; i < 1u << 16; i++) {
        x = rng_hash(x + i);
        bad += rng_sobol(x, 1) != sobol1_by_directions(x) || rng_sobol(x, 0) != rng_reverse_bits(x);
    }
    CHECK_EQ_INT(bad, 0);
}

static RenderParams params_with(uint sampler, uint seed)
{
    RenderParams p;
    memset(&p, 0, sizeof p);
    p.sampler = sampler;
    p.seed = seed;
    return p;
}

static void test_range(void)
{
    uint bad = 0;
    for (uint s = 0; s < 2; s++) {
        RenderParams p = params_with(s ? SAMPLER_INDEPENDENT : SAMPLER_SOBOL, 7);
        for (uint pixel = 0; pixel < 64; pixel++)
            for (uint sample = 0; sample < 256; sample++) {
                RngKey k = rng_key_make(&p, pixel * 7919u, sample);
                for (uint b = 0; b < 4; b++)
                    for (uint d = 0; d < RNG_DIMS_PER_BOUNCE; d++) {
                        float u = rng_uniform(k, b, d);
                        bad += !(u >= 0.0f && u < 1.0f);
                    }
            }
    }
    CHECK_EQ_INT(bad, 0);
    /* the largest 24-bit value maps to the largest float below 1 */
    CHECK((float)(0xffffffffu >> 8) * 5.9604645e-8f < 1.0f);
}

/* Whether points [first, first + 2^m) of a pixel's pair (dx, dy) at bounce b are a
 * (0,m,2)-net: for every split a + (m - a), each of the 2^m intervals of 2^-a by
 * 2^-(m-a) holds exactly one point. */
static int pair_is_net(const RenderParams *p, uint pixel, uint first, uint m, uint b, uint dx, uint dy)
{
    uint n = 1u << m;
    uint *xs = malloc(n * sizeof *xs), *ys = malloc(n * sizeof *ys);
    unsigned char *seen = malloc(n);
    int ok = 1;
    for (uint i = 0; i < n; i++) {
        RngKey k = rng_key_make(p, pixel, first + i);
        xs[i] = (uint)(rng_uniform(k, b, dx) * 16777216.0f);   /* the 24 bits drawn */
        ys[i] = (uint)(rng_uniform(k, b, dy) * 16777216.0f);
    }
    for (uint a = 0; a <= m && ok; a++) {
        memset(seen, 0, n);
        for (uint i = 0; i < n; i++) {
            uint cell = (xs[i] >> (24 - a) << (m - a)) | (m == a ? 0u : ys[i] >> (24 - (m - a)));
            if (seen[cell]++) ok = 0;
        }
    }
    free(xs);
    free(ys);
    free(seen);
    return ok;
}

static int dim_is_stratified(const RenderParams *p, uint pixel, uint first, uint m, uint b, uint d)
{
    uint n = 1u << m;
    unsigned char *seen = calloc(n, 1);
    int ok = 1;
    for (uint i = 0; i < n; i++) {
        uint x = (uint)(rng_uniform(rng_key_make(p, pixel, first + i), b, d) * 16777216.0f);
        if (seen[x >> (24 - m)]++) ok = 0;
    }
    free(seen);
    return ok;
}

static void test_stratification(void)
{
    RenderParams p = params_with(SAMPLER_SOBOL, 11);
    static const uint pairs[][2] = { { DIM_PIXEL_X, DIM_PIXEL_Y }, { DIM_LENS_U, DIM_LENS_V },
                                     { DIM_LIGHT_U, DIM_LIGHT_V }, { DIM_BSDF_U, DIM_BSDF_V } };
    static const uint singles[] = { DIM_LIGHT_PICK, DIM_BSDF_LOBE, DIM_BSDF_W, DIM_ROULETTE };
    uint nets = 0, bad = 0;
    for (uint pixel = 0; pixel < 3; pixel++)
        for (uint b = 0; b < 3; b++)
            for (uint m = 1; m <= 10; m++) {
                /* the first block and a later aligned one (a resumed or batched render) */
                uint firsts[2] = { 0, 5u << m };
                for (uint f = 0; f < 2; f++) {
                    for (uint q = 0; q < 4; q++, nets++)
                        if (!pair_is_net(&p, pixel * 1000u, firsts[f], m, b, pairs[q][0], pairs[q][1])) {
                            bad++;
                            fprintf(stderr, "  not a net: pixel %u bounce %u dims %u,%u, 2^%u from %u\n",
                                    pixel * 1000u, b, pairs[q][0], pairs[q][1], m, firsts[f]);
                        }
                    for (uint q = 0; q < 4; q++, nets++)
                        bad += !dim_is_stratified(&p, pixel * 1000u, firsts[f], m, b, singles[q]);
                }
            }
    fprintf(stderr, "  %u point sets checked for (0,m,2)-nets and 1D strata\n", nets);
    CHECK_EQ_INT(bad, 0);
    /* the independent sampler is no net: the check can fail */
    RenderParams ind = params_with(SAMPLER_INDEPENDENT, 11);
    CHECK(!pair_is_net(&ind, 0, 0, 6, 0, DIM_PIXEL_X, DIM_PIXEL_Y));
}

/* Scrambling and shuffling decorrelate: two pixels, two pairs of a pixel, and the same
 * pair at two bounces never draw the same sequence, and the mean over a pixel's samples
 * is close to 1/2. */
static void test_decorrelation(void)
{
    RenderParams p = params_with(SAMPLER_SOBOL, 3);
    enum { N = 64 };
    uint same_pixel = 0, same_pair = 0, same_bounce = 0;
    double sum = 0.0;
    for (uint i = 0; i < N; i++) {
        RngKey a = rng_key_make(&p, 10, i), b = rng_key_make(&p, 11, i);
        float u = rng_uniform(a, 1, DIM_BSDF_U);
        same_pixel += u == rng_uniform(b, 1, DIM_BSDF_U);
        same_pair += u == rng_uniform(a, 1, DIM_LIGHT_U);
        same_bounce += u == rng_uniform(a, 2, DIM_BSDF_U);
        sum += (double)u;
    }
    CHECK(same_pixel < 4 && same_pair < 4 && same_bounce < 4);
    CHECK_NEAR(sum / N, 0.5, 1.0 / N);
    /* the seed changes every value */
    RenderParams q = params_with(SAMPLER_SOBOL, 4);
    CHECK(rng_uniform(rng_key_make(&p, 10, 5), 0, DIM_PIXEL_X) != rng_uniform(rng_key_make(&q, 10, 5), 0, DIM_PIXEL_X));
}

/* ------------------------------------------------------------ OpenCL against C */

static const char *kernel_src =
    "#include \"sample/rng.h\"\n"
    "__kernel void k_rng(__global const RenderParams *p, __global uint *out, uint n_samples)\n"
    "{\n"
    "    uint i = (uint)get_global_id(0);\n"
    "    uint pixel = i / n_samples * 977u, sample = i % n_samples;\n"
    "    RngKey k = rng_key_make(p, pixel, sample);\n"
    "    for (uint b = 0u; b < 3u; b++)\n"
    "        for (uint d = 0u; d < (uint)RNG_DIMS_PER_BOUNCE; d++)\n"
    "            out[(i * 3u + b) * (uint)RNG_DIMS_PER_BOUNCE + d] = as_uint(rng_uniform(k, b, d));\n"
    "}\n";

/* The OpenCL device the tests compare with C: the first CPU device (PoCL, which make
 * test installs), else the first device; with CLPT_TEST_OPENCL=gpu the first GPU
 * (tools/gpu-check.sh). Into *dev, and its --device index into spec. 0 when there is
 * none, which is a failure, not a skip. */
static int opencl_test_device(OclDeviceInfo *dev, char *spec, size_t spec_size)
{
    OclDeviceInfo *devs = NULL;
    size_t n_dev = 0, pick = 0;
    Error err = { 0 };
    if (ocl_enumerate(&devs, &n_dev, &err) != ST_OK || n_dev == 0) {
        CHECK_MSG(0, "no OpenCL device: %s", err.msg);
        free(devs);
        error_clear(&err);
        return 0;
    }
    if (TEST_OPENCL_IS_GPU) pick = n_dev;
    for (size_t i = 0; i < n_dev; i++)
        if (devs[i].type & (TEST_OPENCL_IS_GPU ? CL_DEVICE_TYPE_GPU : CL_DEVICE_TYPE_CPU)) { pick = i; break; }
    if (pick == n_dev) {
        CHECK_MSG(0, "CLPT_TEST_OPENCL=gpu: no OpenCL GPU");
        free(devs);
        return 0;
    }
    *dev = devs[pick];
    snprintf(spec, spec_size, "%zu", pick);
    free(devs);
    return 1;
}

static void test_opencl_matches_c(void)
{
    OclDeviceInfo dev;
    char spec[24];
    if (!opencl_test_device(&dev, spec, sizeof spec)) return;
    char dir[] = "/tmp/clpt-test-sampler-XXXXXX", path[128], inc[1200], cwd[1024];
    CHECK(mkdtemp(dir) != NULL);
    CHECK(getcwd(cwd, sizeof cwd) != NULL);
    snprintf(path, sizeof path, "%s/entry.cl", dir);
    snprintf(inc, sizeof inc, "-I %s/kernels", cwd);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs(kernel_src, f);
    fclose(f);
    cl_int rc;
    cl_context ctx = clCreateContext(NULL, 1, &dev.id, NULL, NULL, &rc);
    CHECK_EQ_INT(rc, CL_SUCCESS);
    cl_command_queue q = clCreateCommandQueue(ctx, dev.id, 0, &rc);
    CHECK_EQ_INT(rc, CL_SUCCESS);
    cl_program prog = NULL;
    Error err = { 0 };
    Status st = ocl_program_build(ctx, &dev, dir, inc, &prog, NULL, &err);
    CHECK_MSG(st == ST_OK, "%s\n%s", err.msg, err.detail ? err.detail : "");
    error_clear(&err);
    unlink(path);
    rmdir(dir);
    cl_kernel k = NULL;
    if (st == ST_OK) CHECK(ocl_program_kernel(prog, &dev, "k_rng", &k, &err) == ST_OK);
    enum { PIXELS = 32, SAMPLES = 64, N = PIXELS * SAMPLES, PER = 3 * RNG_DIMS_PER_BOUNCE };
    uint *dout = malloc(N * PER * sizeof *dout);
    for (uint s = 0; k && s < 2; s++) {
        RenderParams p = params_with(s ? SAMPLER_INDEPENDENT : SAMPLER_SOBOL, 1234567u);
        cl_mem pb = clCreateBuffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof p, &p, &rc);
        cl_mem ob = clCreateBuffer(ctx, CL_MEM_WRITE_ONLY, N * PER * sizeof *dout, NULL, &rc);
        uint n_samples = SAMPLES;
        size_t global = N;
        clSetKernelArg(k, 0, sizeof pb, &pb);
        clSetKernelArg(k, 1, sizeof ob, &ob);
        clSetKernelArg(k, 2, sizeof n_samples, &n_samples);
        CHECK_EQ_INT(clEnqueueNDRangeKernel(q, k, 1, NULL, &global, NULL, 0, NULL, NULL), CL_SUCCESS);
        CHECK_EQ_INT(clEnqueueReadBuffer(q, ob, CL_TRUE, 0, N * PER * sizeof *dout, dout, 0, NULL, NULL), CL_SUCCESS);
        uint exact = 0;
        for (uint i = 0; i < N; i++) {
            RngKey key = rng_key_make(&p, i / SAMPLES * 977u, i % SAMPLES);
            for (uint b = 0; b < 3; b++)
                for (uint d = 0; d < RNG_DIMS_PER_BOUNCE; d++) {
                    float u = rng_uniform(key, b, d);
                    uint bits;
                    memcpy(&bits, &u, sizeof bits);
                    exact += bits == dout[(i * 3 + b) * RNG_DIMS_PER_BOUNCE + d];
                }
        }
        fprintf(stderr, "  %s sampler: %u of %u values bit-identical on %s and C\n", s ? "independent" : "sobol",
                exact, (uint)(N * PER), dev.name);
        CHECK_EQ_INT(exact, N * PER);
        clReleaseMemObject(pb);
        clReleaseMemObject(ob);
    }
    free(dout);
    if (k) clReleaseKernel(k);
    if (prog) clReleaseProgram(prog);
    clReleaseCommandQueue(q);
    clReleaseContext(ctx);
}

/* ------------------------------------------------------------ whole images */

/* The Cornell box at 32x32 with `spp` samples, sampler and seed, into a float image
 * (32 * 32 * 3, the caller frees); NULL when it failed. */
static float *cornell(const char *devices, uint sampler, uint spp, uint seed, Film *keep)
{
    Scene s;
    Error err = { 0 };
    scene_init(&s);
    Status st = scene_load("scenes/cornell-box.scene", &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    s.image.width = s.image.height = 32;
    s.image.spp = spp;
    s.image.seed = seed;
    s.image.sampler = sampler;
    Film f;
    float *rgb = NULL;
    if (st == ST_OK) {
        st = render_util_run(&s, devices, 0, &f, &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
    }
    if (st == ST_OK) {
        rgb = malloc(32 * 32 * 3 * sizeof *rgb);
        film_resolve(&f, rgb);
        if (keep) *keep = f;
        else film_free(&f);
    }
    scene_free(&s);
    error_clear(&err);
    return rgb;
}

static void test_independent_images_opencl_equals_scalar(void)
{
    OclDeviceInfo dev;
    char spec[24];
    if (!opencl_test_device(&dev, spec, sizeof spec)) return;
    Film a, b;
    float *ra = cornell(spec, SAMPLER_INDEPENDENT, 8, 5, &a), *rb = cornell("scalar", SAMPLER_INDEPENDENT, 8, 5, &b);
    if (ra && rb) {
        CHECK(memcmp(a.sum, b.sum, 32 * 32 * 3 * sizeof *a.sum) == 0);
        film_free(&a);
        film_free(&b);
    }
    free(ra);
    free(rb);
}

static double rmse(const float *a, const float *ref)
{
    double s = 0.0;
    for (int i = 0; i < 32 * 32 * 3; i++) s += ((double)a[i] - ref[i]) * ((double)a[i] - ref[i]);
    return sqrt(s / (32 * 32 * 3));
}

/* Less error per sample: at 16 spp the Sobol image is closer to a 1024-spp reference
 * than the independent one, over two seeds. */
static void test_sobol_has_less_error(void)
{
    float *ref = cornell("scalar", SAMPLER_INDEPENDENT, 1024, 99, NULL);
    double e[2] = { 0.0, 0.0 };
    for (uint seed = 1; seed <= 2 && ref; seed++)
        for (uint k = 0; k < 2; k++) {
            float *img = cornell("scalar", k ? SAMPLER_INDEPENDENT : SAMPLER_SOBOL, 16, seed, NULL);
            if (img) e[k] += rmse(img, ref) / 2.0;
            free(img);
        }
    fprintf(stderr, "  Cornell box 32x32, 16 spp: RMSE sobol %.5f, independent %.5f (MSE ratio %.2f)\n", e[0], e[1],
            e[0] > 0.0 ? e[1] * e[1] / (e[0] * e[0]) : 0.0);
    CHECK(ref && e[0] > 0.0 && e[0] < 0.9 * e[1]);
    free(ref);
}

int main(void)
{
    RUN(test_first_points);
    RUN(test_range);
    RUN(test_stratification);
    RUN(test_decorrelation);
    RUN(test_opencl_matches_c);
    RUN(test_independent_images_opencl_equals_scalar);
    RUN(test_sobol_has_less_error);
    return harness_report();
}
