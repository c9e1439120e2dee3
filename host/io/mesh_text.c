/* mesh_text.c — numbers and paths for the text mesh readers (mesh_text.h). */
#include "io/mesh_text.h"

#include <ctype.h>
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

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

/* ------------------------------------------------------------------ paths */

static int path_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Replaces the component path[start, end) by a directory entry of the folder path[0,
 * start) that equals it without regard to case; 0 when there is none. Entries have the
 * same length as the component when they match, so the path is rewritten in place. */
static int match_component(char *path, size_t start, size_t end)
{
    char saved = path[start];
    size_t len = end - start;
    char name[256];
    if (len >= sizeof name) return 0;
    memcpy(name, path + start, len);
    name[len] = '\0';
    path[start] = '\0';
    DIR *d = opendir(start == 0 ? "." : path);
    path[start] = saved;
    if (!d) return 0;
    int found = 0;
    struct dirent *e;
    while (!found && (e = readdir(d)) != NULL) {
        if (strlen(e->d_name) == len && strcasecmp(e->d_name, name) == 0) {
            memcpy(path + start, e->d_name, len);
            found = 1;
        }
    }
    closedir(d);
    return found;
}

char *mesh_resolve_path(const char *beside, const char *name, size_t len)
{
    const char *slash = strrchr(beside, '/');
    size_t dir = (len > 0 && (name[0] == '/' || name[0] == '\\')) || !slash ? 0 : (size_t)(slash - beside) + 1;
    char *out = malloc(dir + len + 1);
    if (!out) return NULL;
    memcpy(out, beside, dir);
    for (size_t i = 0; i < len; i++) out[dir + i] = name[i] == '\\' ? '/' : name[i];
    out[dir + len] = '\0';
    if (path_exists(out)) return out;
    char *fixed = malloc(dir + len + 1);
    if (!fixed) return out;
    memcpy(fixed, out, dir + len + 1);
    size_t n = dir + len, start = 0;
    while (start < n) {
        while (start < n && fixed[start] == '/') start++;
        size_t end = start;
        while (end < n && fixed[end] != '/') end++;
        if (end == start) break;
        char saved = fixed[end];
        fixed[end] = '\0';
        int exists = path_exists(fixed);
        fixed[end] = saved;
        if (!exists && !match_component(fixed, start, end)) {
            free(fixed);
            return out;
        }
        start = end;
    }
    free(out);
    return fixed;
}
