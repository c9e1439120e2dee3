/* kd_flatten.c — the built tree laid out for the kernels: nodes in depth-first order
 * and the leaves' records (docs/kdtree.md), written by several threads into place so
 * the result does not depend on their number, with the tree's statistics. */
#include "accel/kd_build.h"

#include <stdlib.h>
#include <string.h>

#include "base/jobs.h"
#include "base/pages.h"

/* scale: the product of the empty-space bonus over the node's ancestors that have an
 * empty child (the factor the builder's cost applies to this node's terms). */
typedef struct { const BNode *node; uint parent; int depth; Aabb box; double scale; } FlatItem;

static int leaf_is_empty(const BNode *n) { return n->axis == KD_LEAF && n->count == 0; }

/* A leaf's sorted global ids. */
static const uint *leaf_ids(const BNode *n) { return n->count == 1 ? &n->id : n->ids; }

/* How many of a leaf's sorted ids are triangles (they come after the spheres, before
 * the boxes: a contiguous run), and where they start. */
static void ids_split(const uint *ids, uint count, const KdInput *in, uint *first_tri, uint *n_tri)
{
    uint lo = (uint)in->n_spheres, hi = lo + (uint)in->n_triangles;
    uint a = 0, c = 0;
    while (a < count && ids[a] < lo) a++;
    while (a + c < count && ids[a + c] < hi) c++;
    *first_tri = a;
    *n_tri = c;
}

size_t kd_leaf_record_words(const KdInput *in, const uint *ids, uint count)
{
    uint first, nt;
    ids_split(ids, count, in, &first, &nt);
    size_t w = (size_t)(nt + KD_GROUP - 1) / KD_GROUP * KD_GROUP_WORDS;
    uint others = count - nt;
    return w + (others ? 1 + others : 0);
}

uint kd_leaf_record_write(const KdInput *in, const uint *ids, uint count, uint *out)
{
    uint first, nt;
    ids_split(ids, count, in, &first, &nt);
    uint base = (uint)in->n_spheres;
    for (uint g = 0; g < nt; g += KD_GROUP, out += KD_GROUP_WORDS) {
        for (uint l = 0; l < KD_GROUP; l++) {
            uint id = ids[first + (g + l < nt ? g + l : nt - 1)];
            const Triangle *t = &in->triangles[id - base];
            const vec3 *c[3] = { &t->p0, &t->p1, &t->p2 };
            out[l] = id;
            for (int v = 0; v < 3; v++) {
                const float f[3] = { c[v]->x, c[v]->y, c[v]->z };
                for (int k = 0; k < 3; k++) memcpy(&out[KD_GROUP + (uint)(3 * v + k) * KD_GROUP + l], &f[k], sizeof(float));
            }
        }
    }
    uint others = count - nt;
    if (others) {
        *out++ = others;
        for (uint i = 0; i < count; i++)
            if (i < first || i >= first + nt) *out++ = ids[i];
    }
    uint ng = (nt + KD_GROUP - 1) / KD_GROUP;
    return KD_LEAF | (others ? KD_LEAF_OTHERS : 0u) | (ng << 3);
}

static void leaf_split_ids(const BNode *n, const KdInput *in, uint *first_tri, uint *n_tri)
{
    ids_split(leaf_ids(n), n->count, in, first_tri, n_tri);
}

static size_t leaf_words(const BNode *n, const KdInput *in)
{
    return kd_leaf_record_words(in, leaf_ids(n), n->count);
}

/* Nodes and words of leaf data of the tree below root, to allocate them exactly. */
static void flat_size(const BNode *root, const KdInput *in, size_t *n_nodes, size_t *n_words)
{
    const BNode *stack[KD_MAX_DEPTH + 2];
    int sp = 0;
    stack[sp++] = root;
    *n_nodes = *n_words = 0;
    while (sp) {
        const BNode *n = stack[--sp];
        ++*n_nodes;
        if (n->axis == KD_LEAF) {
            *n_words += leaf_words(n, in);
        } else {
            stack[sp++] = n->child[1];
            stack[sp++] = n->child[0];
        }
    }
}

static Status flat_alloc(KdTree *t, size_t n_nodes, size_t n_words, Error *err)
{
    if (n_nodes > (UINT32_MAX >> 4) || n_words > UINT32_MAX - 1)
        return error_set(err, ST_INTERNAL, "kd-tree: %zu nodes and %zu words of leaf data do not fit the node layout",
                         n_nodes, n_words);
    /* Cache-line aligned, so that no row of a group's corners straddles two lines (the
     * groups are 320 bytes long; OpenCL buffers are aligned at least as well), and on
     * huge pages when large (base/pages.h): the walk reads both at random. */
    t->nodes = pages_alloc_large(n_nodes * sizeof *t->nodes);
    t->leaf_prims = pages_alloc_large((n_words + 1) * sizeof *t->leaf_prims);
    if (!t->nodes || !t->leaf_prims)
        return error_set(err, ST_INTERNAL, "kd-tree: out of memory for %zu nodes", n_nodes);
    return ST_OK;
}

/* A leaf whose record is still to be written, at `words` in the leaf data. */
typedef struct { const BNode *node; uint words; } LeafRecord;

/* The flat arrays being written, and the sums behind the statistics. */
typedef struct {
    KdTree *t;
    const KdInput *in;
    size_t refs, groups;        /* leaf references, groups of triangles */
    uint words;                 /* leaf data laid out so far */
    LeafRecord *records;        /* the non-empty leaves, in order */
    size_t n_records;
} Flat;

/* Writes leaf node `me` and lists its record for records_write; rel: its box's area
 * relative to the root's. */
static void flat_leaf(Flat *f, const FlatItem *it, uint me, double rel)
{
    const BNode *n = it->node;
    KdStats *st = &f->t->stats;
    st->n_leaves++;
    if (n->count == 0) st->n_empty_leaves++;
    f->refs += n->count;
    st->sah_cost += kd_leaf_cost(n->count) * rel;
    st->sah_cost_bonus += kd_leaf_cost(n->count) * rel * it->scale;
    uint first, nt;
    leaf_split_ids(n, f->in, &first, &nt);
    uint ng = (nt + KD_GROUP - 1) / KD_GROUP;
    f->groups += ng;
    f->t->nodes[me].bits = KD_LEAF | (n->count > nt ? KD_LEAF_OTHERS : 0u) | (ng << 3);
    f->t->nodes[me].data = n->count ? f->words : 0u;
    if (n->count) f->records[f->n_records++] = (LeafRecord){ n, f->words };
    f->words += (uint)leaf_words(n, f->in);
}

/* Writes interior node `me` (its above child's index is added when that is reached)
 * and pushes its children, below on top, onto items. */
static void flat_interior(Flat *f, const FlatItem *it, uint me, double rel, FlatItem *items, int *ip)
{
    const BNode *n = it->node;
    KdStats *st = &f->t->stats;
    int empty_below = leaf_is_empty(n->child[0]), empty_above = leaf_is_empty(n->child[1]);
    double scale = it->scale * (empty_below || empty_above ? KD_EMPTY_BONUS : 1.0);
    st->sah_cost += KD_COST_TRAVERSAL * rel;
    st->sah_cost_bonus += KD_COST_TRAVERSAL * rel * scale;
    uint split_bits;
    memcpy(&split_bits, &n->split, sizeof split_bits);
    f->t->nodes[me].data = split_bits;
    f->t->nodes[me].bits = n->axis | (empty_below ? KD_EMPTY_BELOW : 0u) | (empty_above ? KD_EMPTY_ABOVE : 0u);
    FlatItem above = { n->child[1], me, it->depth + 1, it->box, scale };
    FlatItem below = { n->child[0], NO_INDEX, it->depth + 1, it->box, scale };
    above.box.lo[n->axis] = n->split;
    below.box.hi[n->axis] = n->split;
    items[(*ip)++] = above;
    items[(*ip)++] = below;
}

static void flat_stats_finish(Flat *f)
{
    KdStats *st = &f->t->stats;
    st->n_nodes = f->t->n_nodes;
    uint full = st->n_leaves - st->n_empty_leaves;
    st->mean_prims_per_leaf = full ? (double)f->refs / full : 0.0;
    st->bytes = (size_t)f->t->n_nodes * sizeof(KdNode) + (size_t)f->words * sizeof(uint);
    st->bytes_corners = f->groups * KD_GROUP * 9 * sizeof(float);
}

/* Writes leaf records [first, end): the records are most of the flattening's time
 * (each gathers its triangles' corners), and independent of each other. */
typedef struct { const Flat *f; size_t first, end; } RecordJob;

static void *records_write(void *arg)
{
    const RecordJob *j = arg;
    const Flat *f = j->f;
    for (size_t i = j->first; i < j->end; i++) {
        const BNode *n = f->records[i].node;
        kd_leaf_record_write(f->in, leaf_ids(n), n->count, f->t->leaf_prims + f->records[i].words);
    }
    return NULL;
}

/* Writes the tree into t's node and leaf arrays in depth-first order, the below child
 * first, and sums the statistics on the way; the leaf records are written afterwards,
 * on up to `threads` threads (the result does not depend on how many). */
Status kd_flatten(const BNode *root, const Aabb *root_box, const KdInput *in, int threads, KdTree *t,
                      Error *err)
{
    size_t n_nodes, n_words;
    flat_size(root, in, &n_nodes, &n_words);
    Status s = flat_alloc(t, n_nodes, n_words, err);
    if (s != ST_OK) return s;

    Flat f = { t, in, 0, 0, 0, malloc(n_nodes * sizeof(LeafRecord) + 1), 0 };
    if (!f.records) return error_set(err, ST_INTERNAL, "kd-tree: out of memory for %zu nodes", n_nodes);
    double inv_root = kd_box_half_area(root_box) > 0.0 ? 1.0 / kd_box_half_area(root_box) : 0.0;
    uint idx = 0;
    FlatItem items[KD_MAX_DEPTH + 2];
    int ip = 0;
    items[ip++] = (FlatItem){ root, NO_INDEX, 0, *root_box, 1.0 };
    while (ip) {
        FlatItem it = items[--ip];
        uint me = idx++;
        if (it.parent != NO_INDEX) t->nodes[it.parent].bits |= me << 4;
        if ((uint)it.depth > t->stats.max_depth) t->stats.max_depth = (uint)it.depth;
        double rel = inv_root > 0.0 ? kd_box_half_area(&it.box) * inv_root : 1.0;
        if (it.node->axis == KD_LEAF) flat_leaf(&f, &it, me, rel);
        else flat_interior(&f, &it, me, rel, items, &ip);
    }
    t->n_nodes = idx;
    t->n_leaf_prims = f.words;
    flat_stats_finish(&f);

    int n_jobs = jobs_threads(threads, f.n_records, 2048);
    RecordJob jobs[JOBS_MAX];
    for (int i = 0; i < n_jobs; i++)
        jobs[i] = (RecordJob){ &f, f.n_records * (size_t)i / (size_t)n_jobs, f.n_records * (size_t)(i + 1) / (size_t)n_jobs };
    jobs_run(records_write, jobs, sizeof *jobs, n_jobs);
    free(f.records);
    return ST_OK;
}

/* A leaf's primitive ids (its triangles without the repeated lanes, then the others). */
uint kd_leaf_ids(const KdTree *t, uint node, uint *out, uint cap)
{
    KdNode n = t->nodes[node];
    uint m = 0;
    if ((n.bits & 3u) != KD_LEAF) return 0;
    const uint *g = t->leaf_prims + n.data;
    for (uint i = 0; i < n.bits >> 3; i++, g += KD_GROUP_WORDS)
        for (uint l = 0; l < KD_GROUP; l++)
            if ((l == 0 || g[l] != g[l - 1]) && m < cap) out[m++] = g[l];
    if (n.bits & KD_LEAF_OTHERS)
        for (uint i = 1; i <= g[0]; i++)
            if (m < cap) out[m++] = g[i];
    return m;
}

