/* mesh_text.c — numbers for the text mesh readers (mesh_text.h). */
#include "io/mesh_text.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ numbers */

static const float pow10_exact[11] = { 1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f,
                                       1e6f, 1e7f, 1e8f, 1e9f, 1e10f };

/* The fast path takes plain decimals whose digits form an integer m <= 2^24 with at most
 * 10 of them after the point: m and 10^k (k <= 10, since 5^10 < 2^24) are then exact
 * floats, so the single IEEE division m / 10^k is the correctly rounded value, which is
 * strtof's answer. Everything else (exponents, long mantissas, hex) goes to strtof. */
const char *mesh_parse_float(const char *p, const char *end, float *out)
{
    const char *q = p;
    if (q >= end || isspace((unsigned char)*q)) return NULL;
    int neg = 0;
    if (*q == '-' || *q == '+') neg = *q++ == '-';
    uint64_t m = 0;
    int digits = 0, frac = 0, seen_point = 0, any = 0;
    for (; q < end; q++) {
        char c = *q;
        if (c >= '0' && c <= '9') {
            if (digits < 19) m = m * 10 + (uint64_t)(c - '0');
            digits += m > 0;            /* leading zeros are free */
            frac += seen_point;
            any = 1;
        } else if (c == '.' && !seen_point) {
            seen_point = 1;
        } else {
            break;
        }
    }
    /* anything that could continue a number (an exponent, hex, inf, nan) is strtof's */
    int more = q < end && (isalnum((unsigned char)*q) || *q == '.' || *q == '_');
    if (any && !more && digits < 19 && m <= (1u << 24) && frac <= 10) {
        float v = (float)m / pow10_exact[frac];
        *out = neg ? -v : v;
        return q;
    }
    char *e;
    float v = strtof(p, &e);
    if (e == p || !isfinite(v)) return NULL;
    *out = v;
    return e;
}

