/* test_strmap.c — the string map (host/base/strmap.c): lookups by (pointer, length),
 * the first definition winning in strmap_add, replacement in strmap_set, growth, keys
 * with NUL bytes and the empty key, and copies independent of the caller's strings. */
#include "harness.h"

#include "base/strmap.h"

#include <stdio.h>
#include <string.h>

static void test_add_find_set(void)
{
    StrMap m;
    memset(&m, 0, sizeof m);
    uint32_t v = 7;
    CHECK(!strmap_find(&m, "a", 1, &v));
    CHECK_EQ_INT(v, 7);
    CHECK_EQ_INT(strmap_add(&m, "a", 1, 10), 0);
    CHECK_EQ_INT(strmap_add(&m, "ab", 2, 11), 0);
    CHECK_EQ_INT(strmap_add(&m, "a", 1, 12), 1);   /* present: the first value stays */
    CHECK(strmap_find(&m, "a", 1, &v) && v == 10);
    CHECK(strmap_find(&m, "abc", 2, &v) && v == 11);   /* by length: "ab" */
    CHECK(!strmap_find(&m, "b", 1, NULL));
    CHECK_EQ_INT(strmap_set(&m, "a", 1, 13), 0);
    CHECK(strmap_find(&m, "a", 1, &v) && v == 13);
    CHECK_EQ_INT(strmap_set(&m, "c", 1, 14), 0);
    CHECK(strmap_find(&m, "c", 1, &v) && v == 14);
    CHECK_EQ_INT(m.n, 3);
    /* the empty key and keys with NUL bytes are keys like any other */
    CHECK_EQ_INT(strmap_add(&m, "", 0, 20), 0);
    CHECK_EQ_INT(strmap_add(&m, "x\0y", 3, 21), 0);
    CHECK_EQ_INT(strmap_add(&m, "x\0z", 3, 22), 0);
    CHECK(strmap_find(&m, "", 0, &v) && v == 20);
    CHECK(strmap_find(&m, "x\0z", 3, &v) && v == 22);
    CHECK(!strmap_find(&m, "x", 1, NULL));
    strmap_free(&m);
    CHECK_EQ_INT(m.n, 0);
    CHECK(!strmap_find(&m, "a", 1, NULL));
    strmap_free(&m);   /* twice is fine: a freed map is empty */
}

/* 100,000 keys through many doublings, each found with its value; the keys are copies,
 * so the buffer they were made in can be reused. */
static void test_growth(void)
{
    enum { N = 100000 };
    StrMap m;
    memset(&m, 0, sizeof m);
    char key[32];
    int added = 0;
    for (int i = 0; i < N; i++) {
        int n = snprintf(key, sizeof key, "key%d", i);
        added += strmap_add(&m, key, (size_t)n, (uint32_t)i) == 0;
    }
    CHECK_EQ_INT(added, N);
    CHECK_EQ_INT(m.n, N);
    CHECK(m.cap >= 2 * (size_t)N);   /* at most half full */
    int found = 0;
    for (int i = 0; i < N; i++) {
        int n = snprintf(key, sizeof key, "key%d", i);
        uint32_t v;
        found += strmap_find(&m, key, (size_t)n, &v) && v == (uint32_t)i;
    }
    CHECK_EQ_INT(found, N);
    CHECK(!strmap_find(&m, "key100000", 9, NULL));
    strmap_free(&m);
}

int main(void)
{
    RUN(test_add_find_set);
    RUN(test_growth);
    return harness_report();
}
