/*
 * fuzz_merge.c — `clpt merge` (host/dist/merge.c) and the checkpoint reader under it
 * (host/render/checkpoint.c) on arbitrary parts. The input is two parts: its first 4
 * bytes (little-endian) say how long the first is, and the rest is the second. Each is
 * written to a temporary file and the two are merged as `merge --denoise` merges them,
 * the parts' denoiser features included (checkpoint format version 4). A merge that
 * succeeds must hold every sample of its render exactly once, as one range, with film
 * values that many samples can produce, and features (if any) of as many samples (4 x
 * for the emission added back); one that fails must say why, with an input or I/O
 * status.
 */
#include "fuzz.h"
#include "dist/merge.h"

#include <stdio.h>
#include <unistd.h>

FUZZ_SEEDS("parts");

static int write_temp_file(char *path, const uint8_t *data, size_t size)
{
    int fd = mkstemp(path);
    if (fd < 0) return -1;
    size_t done = 0;
    while (done < size) {
        ssize_t w = write(fd, data + done, size - done);
        if (w <= 0) break;
        done += (size_t)w;
    }
    close(fd);
    return done == size ? 0 : -1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 4) return 0;
    size_t first = (size_t)data[0] | (size_t)data[1] << 8 | (size_t)data[2] << 16 | (size_t)data[3] << 24;
    size -= 4;
    data += 4;
    if (first > size) first = size;
    char a[] = "/tmp/clpt-fuzz-merge-XXXXXX", b[] = "/tmp/clpt-fuzz-merge-XXXXXX";
    int ok = write_temp_file(a, data, first) == 0 && write_temp_file(b, data + first, size - first) == 0;
    if (ok) {
        const char *parts[2] = { a, b };
        Checkpoint merged;
        Error err = { 0 };
        Status st = merge_parts(parts, 2, 1, &merged, &err);
        if (st == ST_OK) {
            FUZZ_ASSERT(merged.n_done == 1 && merged.done[0].first == 0 && merged.done[0].count == merged.id.spp);
            FUZZ_ASSERT(merged.film.samples == merged.id.spp);
            size_t n = (size_t)merged.film.width * merged.film.height * 3u;
            for (size_t i = 0; i < n; i++) FUZZ_ASSERT(merged.film.sum[i] >= 0);
            FUZZ_ASSERT(merged.n_features == 0 || merged.features_spp == merged.id.spp);
            for (uint k = 0; k < merged.n_features; k++) {
                FUZZ_ASSERT(merged.features[k].samples == (k == CKPT_FEATURE_EMISSION_MORE ? 4u : 1u) * merged.id.spp);
                for (size_t i = 0; i < n; i++) FUZZ_ASSERT(merged.features[k].sum[i] >= 0);
            }
        } else {
            FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
        }
        checkpoint_free(&merged);
        error_clear(&err);
    }
    unlink(a);
    unlink(b);
    return 0;
}
