/*
 * fuzz.h — what every fuzz target includes (docs/fuzzing.md says how to add one).
 *
 * A target is one file, fuzz/fuzz_NAME.c, with
 *
 *     FUZZ_SEEDS("obj");           file extensions that seed the corpus
 *     int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) { ...; return 0; }
 *
 * The Makefile finds it by its name. `make fuzz` builds it with libFuzzer, ASan and
 * UBSan into build-fuzz/fuzz/fuzz_NAME, and tools/fuzz.sh runs it with a corpus seeded
 * from the files under tests/data/ and scenes/ with those extensions (it reads the
 * FUZZ_SEEDS line from the source). `make test` links the same file with fuzz/replay.c
 * into build/tests/test_fuzz_NAME, which feeds it every file of tests/data/fuzz/NAME/
 * (the regression files: each input that once crashed it) and the seed files.
 *
 * A target must not leak, must not print (the replay test and libFuzzer read stdout),
 * and should abort() when the code under test breaks one of its own promises (a
 * message-less error, an index out of range): libFuzzer saves such inputs like crashes.
 */
#ifndef CLPT_FUZZ_H
#define CLPT_FUZZ_H

#include "scene/scene.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Space-separated file extensions, without dots. */
#define FUZZ_SEEDS(exts) const char fuzz_seed_extensions[] = exts
extern const char fuzz_seed_extensions[];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Stops the run when a promise of the code under test is broken: libFuzzer reports an
 * abort as a crash and keeps the input. */
#define FUZZ_ASSERT(cond) do { if (!(cond)) abort(); } while (0)

/* The input as a NUL-terminated string (the text readers want one); NULL when out of
 * memory. Free it. */
static inline char *fuzz_text(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    if (!text) return NULL;
    memcpy(text, data, size);
    text[size] = '\0';
    return text;
}

static inline int fuzz_finite3(vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* What a mesh reader promises of every triangle it appended: finite corners, the given
 * material (NO_INDEX: any material the scene has, as glTF's own), a shading record that
 * exists (or none). */
static inline void fuzz_check_triangles(const Scene *s, uint material)
{
    for (size_t i = 0; i < s->n_triangles; i++) {
        const Triangle *t = &s->triangles[i];
        FUZZ_ASSERT(material == NO_INDEX ? t->material < s->n_materials : t->material == material);
        FUZZ_ASSERT(fuzz_finite3(t->p0) && fuzz_finite3(t->p1) && fuzz_finite3(t->p2));
        FUZZ_ASSERT(t->shading == NO_INDEX || t->shading < s->n_shading);
    }
}

/* What the mesh sink promises of glTF's corner attributes (TriExtra): tri_extra_of is
 * empty or one entry per shading record, a record flagged TRI_HAS_EXTRA names a TriExtra
 * that exists and has attributes, whose values are finite, tangents unit-length (w +1
 * or -1). */
static inline void fuzz_check_extras(const Scene *s)
{
    FUZZ_ASSERT(s->n_tri_extra_of == 0 || s->n_tri_extra_of == s->n_shading);
    FUZZ_ASSERT(s->n_tri_extras == 0 || s->n_tri_extra_of > 0);
    for (size_t i = 0; i < s->n_shading; i++) {
        if (!(s->shading[i].flags & TRI_HAS_EXTRA)) {
            FUZZ_ASSERT(s->n_tri_extra_of == 0 || s->tri_extra_of[i] == NO_INDEX);
            continue;
        }
        FUZZ_ASSERT(i < s->n_tri_extra_of && s->tri_extra_of[i] < s->n_tri_extras);
        const TriExtra *e = &s->tri_extras[s->tri_extra_of[i]];
        FUZZ_ASSERT(e->flags != 0 && (e->flags & ~(EXTRA_TANGENT | EXTRA_COLOR | EXTRA_UV1)) == 0);
        for (int c = 0; c < 3; c++) {
            if (e->flags & EXTRA_TANGENT) {
                const float *t = e->tangent[c];
                double len = sqrt((double)t[0] * t[0] + (double)t[1] * t[1] + (double)t[2] * t[2]);
                FUZZ_ASSERT(fabs(len - 1.0) < 1e-4 && (t[3] == 1.0f || t[3] == -1.0f));
            }
            for (int k = 0; k < 4; k++) FUZZ_ASSERT(!(e->flags & EXTRA_COLOR) || isfinite(e->color[c][k]));
            for (int k = 0; k < 2; k++) FUZZ_ASSERT(!(e->flags & EXTRA_UV1) || isfinite(e->uv[c][k]));
        }
    }
}

#endif /* CLPT_FUZZ_H */
