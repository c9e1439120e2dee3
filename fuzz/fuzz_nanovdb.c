/*
 * fuzz_nanovdb.c — the NanoVDB reader (host/io/nanovdb.c) on arbitrary bytes, read as a
 * .nvdb file for its "density" grid. Seeds: the .nvdb files under tests/data and scenes/
 * (tests/data/nanovdb/gen_nvdb.c writes them). A grid that reads must be within the
 * cell limit, its densities finite and >= 0 and its box not empty; an error is ST_INPUT
 * with a message (or ST_INTERNAL when memory runs out).
 */
#include "fuzz.h"
#include "io/nanovdb.h"

#include <math.h>
#include <stdlib.h>

FUZZ_SEEDS("nvdb");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    NanoDense d;
    Error err = { 0 };
    Status st = nanovdb_read_grid("fuzz.nvdb", data, size, "density", &d, &err);
    if (st) {
        FUZZ_ASSERT((st == ST_INPUT || st == ST_INTERNAL) && err.msg[0]);
        FUZZ_ASSERT(d.density == NULL);
    } else {
        uint64_t cells = (uint64_t)d.nx * d.ny * d.nz;
        FUZZ_ASSERT(d.density && cells >= 1 && cells <= NANOVDB_MAX_CELLS && d.stride >= 1);
        for (uint64_t i = 0; i < cells; i++) FUZZ_ASSERT(d.density[i] >= 0.0f && isfinite(d.density[i]));
        for (int a = 0; a < 3; a++) FUZZ_ASSERT(d.hi[a] > d.lo[a]);
        free(d.density);
    }
    error_clear(&err);
    (void)nanovdb_has_grid(data, size, "temperature");
    return 0;
}
