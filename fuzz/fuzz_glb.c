/*
 * fuzz_glb.c — the GLB container of the glTF reader (host/io/gltf.c, glb_split and what
 * follows it): every input is read as a .glb, twice. First as it is, so the fuzzer
 * explores the 12-byte header (magic, version, total length) and the chunk headers;
 * then with the magic and the total length made right, so that mutations of the chunk
 * lengths and types, the JSON chunk and the BIN chunk behind them get past the header
 * checks instead of being refused at byte 8 (fuzz_gltf.c, which takes a GLB only when
 * the input happens to start with the magic, spends most of its time on the JSON).
 * Every error must carry a message; every triangle must be finite with a valid material
 * and shading index; tangents, colours and second uvs sound (fuzz_check_extras).
 * Seeds: the .glb files under tests/data/ (make_gltf.py writes them: a bare triangle,
 * extras.glb with every corner attribute and a sampler, and the bad containers).
 */
#include "fuzz.h"
#include "io/gltf.h"

#include <string.h>

FUZZ_SEEDS("glb");

static void parse_glb(const char *data, size_t size)
{
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    MeshOptions o = mesh_options(NO_INDEX);
    GltfView view = { NULL, 0, 0 };
    Status st = gltf_parse("fuzz.glb", data, size, &s, &o, &view, &err);
    /* ST_IO: a buffer or image file the JSON names is not there */
    if (st) FUZZ_ASSERT((st == ST_INPUT || st == ST_IO) && err.msg[0]);
    fuzz_check_triangles(&s, NO_INDEX);
    fuzz_check_extras(&s);
    scene_free(&s);
    error_clear(&err);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *copy = fuzz_text(data, size);
    if (!copy) return 0;
    parse_glb(copy, size);
    if (size >= 12) {
        /* the header made right: magic "glTF", version 2, the true length (little-endian) */
        static const unsigned char magic[8] = { 'g', 'l', 'T', 'F', 2, 0, 0, 0 };
        memcpy(copy, magic, sizeof magic);
        for (int i = 0; i < 4; i++) copy[8 + i] = (char)((size >> (8 * i)) & 255u);
        parse_glb(copy, size);
    }
    free(copy);
    return 0;
}
