/*
 * fuzz_lexer.c — the tokenizer (host/io/lexer.c, used by the scene and classic readers) on
 * arbitrary bytes: every token is described and converted as the parsers do, and each
 * must lie inside the text, in order, with positions that only move forward.
 */
#include "fuzz.h"
#include "io/lexer.h"

#include <math.h>
#include <string.h>

FUZZ_SEEDS("scene txt");

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    Lexer lx;
    Error err = { 0 };
    if (lex_open_text(&lx, "fuzz.scene", (const char *)data, size, &err) != ST_OK) {
        error_clear(&err);
        return 0;
    }
    const char *prev_end = lx.src;
    uint prev_line = 1;
    for (;;) {
        Token t;
        Status st = lex_next(&lx, &t, &err);
        if (st) {
            FUZZ_ASSERT(st == ST_INPUT && err.msg[0]);
            break;
        }
        FUZZ_ASSERT(t.line >= prev_line && t.col >= 1);
        if (t.kind == TOK_EOF) break;
        FUZZ_ASSERT(t.text >= prev_end && t.text + t.len <= lx.src + lx.len);
        prev_end = t.text + t.len;
        prev_line = t.line;
        float f;
        unsigned long long u;
        char shown[64];
        tok_describe(&t, shown, sizeof shown);
        FUZZ_ASSERT(memchr(shown, '\0', sizeof shown) != NULL);
        if (tok_float(&t, &f) == 0) FUZZ_ASSERT(isfinite(f));
        (void)tok_uint(&t, &u);
        FUZZ_ASSERT(lex_expected(&lx, &t, "anything", &err) == ST_INPUT);
    }
    lex_close(&lx);
    error_clear(&err);
    return 0;
}
