/* broadphase.c - two dynamic AABB trees, one for moving and one for static
 * proxies, so static geometry is never queried against itself.
 *
 * Insertion picks the sibling of least surface-area cost by a greedy branch
 * and bound descent; on the way back up, each node tries the six swaps of its
 * children and grandchildren and keeps the one that most reduces surface area
 * (tree rotations). That also keeps the tree shallow, sorted input included;
 * only many mutually nested boxes make it deep (a chain: SAH sees no better
 * tree), which costs time, never correctness.
 * A moved-proxy buffer makes pair finding incremental: only moved proxies are
 * queried. Nodes live in one growable pool addressed by index (proxy id =
 * leaf node index); traversals use explicit stacks, never recursion. */
#include <assert.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "broadphase.h"

#define NULL_NODE (-1)
#define LOCAL_STACK 256
#define CACHE_LINE 64

enum { MOVING_TREE = 0, STATIC_TREE = 1 };

/* Exactly 64 bytes, stored cache-line aligned: a traversal reads one line per node. */
typedef struct bp_node {
    aabb box;
    int parent;         /* the next free node while on the free list */
    int child1, child2; /* NULL_NODE in a leaf */
    int height;         /* leaf 0, free -1 */
} bp_node;

/* Per node id, meaningful for leaves (proxies) only: kept out of the hot nodes. */
typedef struct bp_leaf {
    int user;
    int move_slot; /* index in the moved buffer, or -1 */
    int tree;
} bp_leaf;

/* The free nodes, in the order alloc_node hands them out: free_list (the
 * nodes freed since the pool last grew, last freed first), then the fresh
 * nodes fresh .. capacity - 1 (lowest first; never written, so a pool grown
 * by doubling keeps the pages it has not used yet untouched), then
 * tail_list (every node free when the pool grew). That is the order of one
 * list holding the new nodes first, then the old list, written out at each
 * growth (the proxy ids are the same). */
struct broadphase {
    bp_node *nodes;   /* aligned view into node_block */
    void *node_block;
    bp_leaf *leaves;  /* same capacity as nodes */
    int capacity, free_list, free_count;
    int fresh, tail_list;
    int root[2];
    int *moved;       /* proxies moved or created since the last bp_update_pairs */
    int move_count, move_capacity;
    int proxy_count;
};

broadphase *bp_create(void)
{
    broadphase *bp = calloc(1, sizeof *bp);
    if (!bp) return NULL;
    bp->free_list = bp->tail_list = NULL_NODE;
    bp->root[MOVING_TREE] = bp->root[STATIC_TREE] = NULL_NODE;
    return bp;
}

void bp_destroy(broadphase *bp)
{
    if (!bp) return;
    free(bp->node_block);
    free(bp->leaves);
    free(bp->moved);
    free(bp);
}

void bp_clear(broadphase *bp)
{
    bp->free_list = bp->tail_list = NULL_NODE;
    bp->fresh = 0;
    bp->free_count = bp->capacity;
    bp->root[MOVING_TREE] = bp->root[STATIC_TREE] = NULL_NODE;
    bp->move_count = 0;
    bp->proxy_count = 0;
}

/* Makes at least `need` nodes free. Returns 0 on out of memory, changing nothing visible. */
static int reserve_nodes(broadphase *bp, int need)
{
    if (bp->free_count >= need) return 1;
    int old = bp->capacity, cap = old ? old : 64;
    while (cap - old + bp->free_count < need) {
        if (cap > INT_MAX / 2) return 0;
        cap *= 2;
    }
    bp_leaf *leaves = realloc(bp->leaves, sizeof *leaves * (size_t)cap);
    if (!leaves) return 0;
    bp->leaves = leaves; /* larger than needed is harmless if the next step fails */
    void *block = malloc(sizeof(bp_node) * (size_t)cap + CACHE_LINE - 1);
    if (!block) return 0;
    bp_node *nodes = (bp_node *)(((uintptr_t)block + CACHE_LINE - 1) & ~(uintptr_t)(CACHE_LINE - 1));
    if (old) memcpy(nodes, bp->nodes, sizeof *nodes * (size_t)old);
    free(bp->node_block);
    bp->node_block = block;
    bp->nodes = nodes;
    /* the free nodes so far, written out as one list (free_list, the fresh
     * ones left, tail_list), go after the new fresh ones */
    int head = bp->tail_list;
    for (int i = old - 1; i >= bp->fresh; i--) {
        nodes[i].parent = head;
        nodes[i].height = -1;
        head = i;
    }
    if (bp->free_list != NULL_NODE) {
        int last = bp->free_list;
        while (nodes[last].parent != NULL_NODE) last = nodes[last].parent;
        nodes[last].parent = head;
        head = bp->free_list;
    }
    bp->tail_list = head;
    bp->free_list = NULL_NODE;
    bp->fresh = old;
    bp->free_count += cap - old;
    bp->capacity = cap;
    return 1;
}

/* Only called after reserve_nodes: cannot fail. */
static int alloc_node(broadphase *bp)
{
    int id;
    if (bp->free_list != NULL_NODE) {
        id = bp->free_list;
        bp->free_list = bp->nodes[id].parent;
    } else if (bp->fresh < bp->capacity) {
        id = bp->fresh++;
    } else {
        id = bp->tail_list;
        assert(id != NULL_NODE);
        bp->tail_list = bp->nodes[id].parent;
    }
    bp_node *n = &bp->nodes[id];
    bp->free_count--;
    n->parent = n->child1 = n->child2 = NULL_NODE;
    n->height = 0;
    return id;
}

static void free_node(broadphase *bp, int id)
{
    bp->nodes[id].parent = bp->free_list;
    bp->nodes[id].height = -1;
    bp->free_list = id;
    bp->free_count++;
}

static int max_int(int a, int b) { return a > b ? a : b; }
static int is_leaf(const bp_node *n) { return n->child1 == NULL_NODE; }

static double centre_distance2(aabb a, aabb b)
{
    return v3_len2(v3_sub(v3_add(a.lo, a.hi), v3_add(b.lo, b.hi)));
}

/* The node whose new parent (with the leaf) adds the least surface area to the
 * tree: the parent's area plus every ancestor's growth. Descends greedily into
 * the child with the lower bound and stops once neither child can beat the best. */
static int find_best_sibling(const broadphase *bp, int root, aabb box)
{
    const bp_node *N = bp->nodes;
    double leaf_area = aabb_area(box);
    int best = root;
    double best_cost = aabb_area(aabb_union(N[root].box, box));
    double inherited = 0.0; /* growth of the current node and all its ancestors */
    int i = root;
    while (!is_leaf(&N[i])) {
        inherited += aabb_area(aabb_union(N[i].box, box)) - aabb_area(N[i].box);
        int c[2] = {N[i].child1, N[i].child2};
        double lower[2];
        for (int k = 0; k < 2; k++) {
            double direct = aabb_area(aabb_union(N[c[k]].box, box));
            double cost = direct + inherited;
            if (cost < best_cost) {
                best_cost = cost;
                best = c[k];
            }
            /* a sibling below c[k]: c[k] grows, and the new parent is at least the leaf */
            lower[k] = is_leaf(&N[c[k]]) ? HUGE_VAL : inherited + direct - aabb_area(N[c[k]].box) + leaf_area;
        }
        if (best_cost <= lower[0] && best_cost <= lower[1]) break;
        int pick;
        if (lower[0] != lower[1]) pick = lower[0] < lower[1] ? 0 : 1;
        else pick = centre_distance2(N[c[0]].box, box) <= centre_distance2(N[c[1]].box, box) ? 0 : 1;
        i = c[pick];
    }
    return best;
}

/* Replaces child `old_child` of node `parent` (or the root) by `new_child`. */
static void replace_child(broadphase *bp, int tree, int parent, int old_child, int new_child)
{
    bp_node *N = bp->nodes;
    N[new_child].parent = parent;
    if (parent == NULL_NODE) bp->root[tree] = new_child;
    else if (N[parent].child1 == old_child) N[parent].child1 = new_child;
    else N[parent].child2 = new_child;
}

static void refit(bp_node *N, int i)
{
    int a = N[i].child1, b = N[i].child2;
    N[i].box = aabb_union(N[a].box, N[b].box);
    N[i].height = 1 + max_int(N[a].height, N[b].height);
}

/* Puts node x where node y is and y where x was (neither an ancestor of the
 * other); only the parents' links change, their boxes are refit by the caller. */
static void exchange(bp_node *N, int x, int y)
{
    int px = N[x].parent, py = N[y].parent;
    if (N[px].child1 == x) N[px].child1 = y;
    else N[px].child2 = y;
    if (N[py].child1 == y) N[py].child1 = x;
    else N[py].child2 = x;
    N[x].parent = py;
    N[y].parent = px;
}

/* Tree rotations (Kensler 2008) at node a with children b = (d, e) and
 * c = (f, g): exchanging a child with a grandchild on the other side (b<->f,
 * b<->g, c<->d, c<->e) or two grandchildren (d<->f, d<->g) keeps a's box and
 * changes only b's and c's. Applies the one that most reduces their summed
 * surface area, if any does. */
static void rotate(bp_node *N, int a)
{
    if (N[a].height < 2) return;
    int b = N[a].child1, c = N[a].child2;
    double area_b = aabb_area(N[b].box), area_c = aabb_area(N[c].box);
    double best_gain = 0.0;
    int best_x = NULL_NODE, best_y = NULL_NODE;
    for (int k = 0; k < 2; k++) {
        int child = k ? c : b, uncle = k ? b : c;
        if (is_leaf(&N[uncle])) continue;
        double uncle_area = k ? area_b : area_c;
        int g1 = N[uncle].child1, g2 = N[uncle].child2;
        /* child <-> g1 leaves the uncle holding child and g2 */
        double gain1 = uncle_area - aabb_area(aabb_union(N[child].box, N[g2].box));
        double gain2 = uncle_area - aabb_area(aabb_union(N[child].box, N[g1].box));
        if (gain1 > best_gain) { best_gain = gain1; best_x = child; best_y = g1; }
        if (gain2 > best_gain) { best_gain = gain2; best_x = child; best_y = g2; }
    }
    if (!is_leaf(&N[b]) && !is_leaf(&N[c])) {
        int d = N[b].child1, e = N[b].child2, f = N[c].child1, g = N[c].child2;
        /* d <-> f gives b = (f, e), c = (d, g); d <-> g gives b = (g, e), c = (f, d) */
        double gain_f = area_b + area_c - aabb_area(aabb_union(N[f].box, N[e].box)) -
                        aabb_area(aabb_union(N[d].box, N[g].box));
        double gain_g = area_b + area_c - aabb_area(aabb_union(N[g].box, N[e].box)) -
                        aabb_area(aabb_union(N[f].box, N[d].box));
        if (gain_f > best_gain) { best_gain = gain_f; best_x = d; best_y = f; }
        if (gain_g > best_gain) { best_gain = gain_g; best_x = d; best_y = g; }
    }
    if (best_x == NULL_NODE) return;
    exchange(N, best_x, best_y);
    /* b or c may have moved below the other, but keeps its own children */
    if (!is_leaf(&N[b])) refit(N, b);
    if (!is_leaf(&N[c])) refit(N, c);
    refit(N, a);
}

/* Refits boxes and heights from node i up, rotating on the way; stops after
 * the first node whose box and height come out unchanged, as nothing above it
 * changes (rotating further up bought no measurable quality). */
static void refit_up(broadphase *bp, int i)
{
    bp_node *N = bp->nodes;
    while (i != NULL_NODE) {
        aabb before = N[i].box;
        int height = N[i].height;
        refit(N, i);
        rotate(N, i);
        if (height == N[i].height && memcmp(&before, &N[i].box, sizeof before) == 0) break;
        i = N[i].parent;
    }
}

/* The tree must have a free node reserved for the new parent. */
static void insert_leaf(broadphase *bp, int tree, int leaf)
{
    if (bp->root[tree] == NULL_NODE) {
        bp->root[tree] = leaf;
        bp->nodes[leaf].parent = NULL_NODE;
        return;
    }
    int sibling = find_best_sibling(bp, bp->root[tree], bp->nodes[leaf].box);
    int parent = alloc_node(bp);
    bp_node *N = bp->nodes;
    int old_parent = N[sibling].parent;
    N[parent].child1 = sibling;
    N[parent].child2 = leaf;
    N[leaf].parent = parent;
    replace_child(bp, tree, old_parent, sibling, parent);
    N[sibling].parent = parent;
    refit(N, parent);
    rotate(N, parent);
    refit_up(bp, old_parent);
}

/* Frees the leaf's parent node. */
static void remove_leaf(broadphase *bp, int tree, int leaf)
{
    bp_node *N = bp->nodes;
    if (leaf == bp->root[tree]) {
        bp->root[tree] = NULL_NODE;
        return;
    }
    int parent = N[leaf].parent, grand = N[parent].parent;
    int sibling = N[parent].child1 == leaf ? N[parent].child2 : N[parent].child1;
    replace_child(bp, tree, grand, parent, sibling);
    free_node(bp, parent);
    /* refit only (rotating here costs time and buys no measurable quality),
     * and stop where nothing changes */
    for (int i = grand; i != NULL_NODE; i = N[i].parent) {
        aabb before = N[i].box;
        int height = N[i].height;
        refit(N, i);
        if (height == N[i].height && memcmp(&before, &N[i].box, sizeof before) == 0) break;
    }
}

static void mark_moved(broadphase *bp, int proxy)
{
    bp_leaf *l = &bp->leaves[proxy];
    if (l->move_slot >= 0) return;
    assert(bp->move_count < bp->move_capacity); /* reserved at creation */
    l->move_slot = bp->move_count;
    bp->moved[bp->move_count++] = proxy;
}

static void unmark_moved(broadphase *bp, int proxy)
{
    int slot = bp->leaves[proxy].move_slot;
    if (slot < 0) return;
    int last = bp->moved[--bp->move_count];
    bp->moved[slot] = last;
    bp->leaves[last].move_slot = slot;
    bp->leaves[proxy].move_slot = -1;
}

static int is_proxy(const broadphase *bp, int proxy)
{
    return bp && proxy >= 0 && proxy < bp->fresh && bp->nodes[proxy].height == 0; /* (fresh ones are unwritten) */
}

int bp_create_proxy(broadphase *bp, aabb box, int is_static, int user)
{
    /* reserve everything first, so failure leaves no trace; the moved buffer
     * holds every proxy, so marking one moved never allocates */
    if (!reserve_nodes(bp, 2)) return -1;
    if (!array_reserve((void **)&bp->moved, &bp->move_capacity, bp->proxy_count + 1, sizeof *bp->moved)) return -1;
    int tree = is_static ? STATIC_TREE : MOVING_TREE;
    int leaf = alloc_node(bp);
    bp->nodes[leaf].box = box;
    bp->leaves[leaf].user = user;
    bp->leaves[leaf].move_slot = -1;
    bp->leaves[leaf].tree = tree;
    insert_leaf(bp, tree, leaf);
    bp->proxy_count++;
    mark_moved(bp, leaf);
    return leaf;
}

/* The k-th smallest of keys[ids[lo..hi)] (by key, then id) at position k, the
 * smaller ones before it and the larger after (quickselect, middle pivot). */
static int key_less(const double *key, int a, int b) { return key[a] < key[b] || (key[a] == key[b] && a < b); }
static void select_kth(int *ids, const double *key, int lo, int hi, int k)
{
    while (hi - lo > 1) {
        int pivot = ids[lo + (hi - lo) / 2], i = lo, j = hi - 1;
        while (i <= j) {
            while (key_less(key, ids[i], pivot)) i++;
            while (key_less(key, pivot, ids[j])) j--;
            if (i <= j) {
                int t = ids[i];
                ids[i] = ids[j];
                ids[j] = t;
                i++;
                j--;
            }
        }
        if (k <= j) hi = j + 1;
        else if (k >= i) lo = i;
        else return;
    }
}

/* A subtree over the leaves ids[lo..hi): split at the median centre along
 * the widest spread of centres. key is scratch, one per node id. */
static int build_subtree(broadphase *bp, int *ids, double *key, int lo, int hi)
{
    bp_node *N = bp->nodes;
    if (hi - lo == 1) return ids[lo];
    vec3 cmin = v3_scale(v3_add(N[ids[lo]].box.lo, N[ids[lo]].box.hi), 0.5), cmax = cmin;
    for (int i = lo + 1; i < hi; i++) {
        vec3 c = v3_scale(v3_add(N[ids[i]].box.lo, N[ids[i]].box.hi), 0.5);
        cmin = v3_min(cmin, c);
        cmax = v3_max(cmax, c);
    }
    vec3 spread = v3_sub(cmax, cmin);
    int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : spread.y >= spread.z ? 1 : 2;
    for (int i = lo; i < hi; i++) {
        aabb b = N[ids[i]].box;
        key[ids[i]] = axis == 0 ? b.lo.x + b.hi.x : axis == 1 ? b.lo.y + b.hi.y : b.lo.z + b.hi.z;
    }
    int mid = lo + (hi - lo) / 2;
    select_kth(ids, key, lo, hi, mid);
    int a = build_subtree(bp, ids, key, lo, mid), b = build_subtree(bp, ids, key, mid, hi);
    int parent = alloc_node(bp);
    N = bp->nodes;
    N[parent].child1 = a;
    N[parent].child2 = b;
    N[a].parent = N[b].parent = parent;
    refit(N, parent);
    return parent;
}

/* A 10-bit cell number spread to every third bit: three of them
 * interleaved (x lowest) are a centre's Z-order (Morton) code. */
static uint32_t spread10(uint32_t v)
{
    v &= 0x3ffu;
    v = (v | v << 16) & 0x030000ffu;
    v = (v | v << 8) & 0x0300f00fu;
    v = (v | v << 4) & 0x030c30c3u;
    v = (v | v << 2) & 0x09249249u;
    return v;
}

static uint32_t cell10(double c, double lo, double scale)
{
    double q = (c - lo) * scale; /* in [0, 1024) but for rounding */
    return q >= 1023.0 ? 1023u : q > 0.0 ? (uint32_t)q : 0u;
}

/* A subtree over ids[lo..hi), sorted by their codes: split where the
 * highest bit in which the range's codes differ turns on (one binary
 * search: the bits above it are common to the range), i.e. along the
 * octree's planes (depth at most 30 so); a range whose codes are all equal
 * (centres in one cell, 1/1024th of the widest extent of the centres: a far
 * body stretches it) falls back to median splits. */
static int morton_subtree(broadphase *bp, int *ids, const uint32_t *code, double *key, int lo, int hi)
{
    if (hi - lo == 1) return ids[lo];
    uint32_t diff = code[lo] ^ code[hi - 1];
    if (!diff) return build_subtree(bp, ids, key, lo, hi);
    uint32_t bit = 1u << 31;
    while (!(diff & bit)) bit >>= 1;
    int a0 = lo, b0 = hi - 1; /* code[a0] has the bit clear, code[b0] set */
    while (b0 - a0 > 1) {
        int m = a0 + (b0 - a0) / 2;
        if (code[m] & bit) b0 = m;
        else a0 = m;
    }
    int a = morton_subtree(bp, ids, code, key, lo, b0), b = morton_subtree(bp, ids, code, key, b0, hi);
    int parent = alloc_node(bp);
    bp_node *N = bp->nodes;
    N[parent].child1 = a;
    N[parent].child2 = b;
    N[a].parent = N[b].parent = parent;
    refit(N, parent);
    return parent;
}

/* ids[0..count) sorted by Morton code (least significant digit radix sort,
 * three 10-bit digits; stable, so equal codes keep their order); code gets
 * the sorted codes. tmp_ids, tmp_code: scratch of count each. */
static void morton_sort(const bp_node *N, int *ids, uint32_t *code, int *tmp_ids, uint32_t *tmp_code, int count)
{
    vec3 cmin = v3_add(N[ids[0]].box.lo, N[ids[0]].box.hi), cmax = cmin; /* centres, doubled */
    for (int i = 1; i < count; i++) {
        vec3 c = v3_add(N[ids[i]].box.lo, N[ids[i]].box.hi);
        cmin = v3_min(cmin, c);
        cmax = v3_max(cmax, c);
    }
    /* cubic cells (one scale for the three axes): a flat world's splits
     * then go across its long axes first, as median splits would */
    vec3 span = v3_sub(cmax, cmin);
    double widest = span.x > span.y ? span.x : span.y;
    if (span.z > widest) widest = span.z;
    double scale = widest > 0 ? 1024.0 / widest : 0.0;
    for (int i = 0; i < count; i++) {
        vec3 c = v3_add(N[ids[i]].box.lo, N[ids[i]].box.hi);
        code[i] = spread10(cell10(c.x, cmin.x, scale)) | spread10(cell10(c.y, cmin.y, scale)) << 1 |
                  spread10(cell10(c.z, cmin.z, scale)) << 2;
    }
    int start[1025];
    for (int shift = 0; shift < 30; shift += 10) {
        memset(start, 0, sizeof start);
        for (int i = 0; i < count; i++) start[(code[i] >> shift & 0x3ffu) + 1]++;
        for (int k = 0; k < 1024; k++) start[k + 1] += start[k];
        for (int i = 0; i < count; i++) {
            int at = start[code[i] >> shift & 0x3ffu]++;
            tmp_ids[at] = ids[i];
            tmp_code[at] = code[i];
        }
        memcpy(ids, tmp_ids, sizeof *ids * (size_t)count);
        memcpy(code, tmp_code, sizeof *code * (size_t)count);
    }
}

int bp_create_proxies(broadphase *bp, const aabb *box, const int *is_static, const int *user, int n, int *proxy)
{
    if (n <= 0) return 1;
    if (bp->proxy_count != 0 || n > INT_MAX / 2 - 1) return 0;
    /* ids and their codes, each followed by the radix sort's scratch of n */
    int *ids = malloc(sizeof *ids * 2 * (size_t)n);
    uint32_t *code = malloc(sizeof *code * 2 * (size_t)n);
    if (!ids || !code || !reserve_nodes(bp, 2 * n) ||
        !array_reserve((void **)&bp->moved, &bp->move_capacity, n, sizeof *bp->moved)) {
        free(ids);
        free(code);
        return 0;
    }
    double *key = malloc(sizeof *key * (size_t)bp->capacity); /* (median fallback's scratch) */
    if (!key) {
        free(ids);
        free(code);
        return 0;
    }
    /* the leaves first, in the order given (lowest free ids first), then the inner nodes */
    for (int i = 0; i < n; i++) {
        int leaf = alloc_node(bp);
        bp->nodes[leaf].box = box[i];
        bp->leaves[leaf].user = user[i];
        bp->leaves[leaf].move_slot = -1;
        bp->leaves[leaf].tree = is_static[i] ? STATIC_TREE : MOVING_TREE;
        bp->proxy_count++;
        mark_moved(bp, leaf);
        proxy[i] = leaf;
    }
    /* Each tree bottom up from the leaves in Z order: one sort by Morton
     * code and one binary search per inner node, where median splits cost
     * a quickselect per level (13.3M instructions for a 10,000-body
     * restore). The trees' shape changes nothing the broadphase reports. */
    for (int tree = 0; tree < 2; tree++) {
        int count = 0;
        for (int i = 0; i < n; i++)
            if (bp->leaves[proxy[i]].tree == tree) ids[count++] = proxy[i];
        if (count == 0) continue;
        morton_sort(bp->nodes, ids, code, ids + n, code + n, count);
        int root = morton_subtree(bp, ids, code, key, 0, count);
        bp->nodes[root].parent = NULL_NODE;
        bp->root[tree] = root;
    }
    free(key);
    free(code);
    free(ids);
    return 1;
}

void bp_destroy_proxy(broadphase *bp, int proxy)
{
    assert(is_proxy(bp, proxy));
    unmark_moved(bp, proxy);
    remove_leaf(bp, bp->leaves[proxy].tree, proxy);
    free_node(bp, proxy);
    bp->proxy_count--;
}

void bp_move_proxy(broadphase *bp, int proxy, aabb box)
{
    assert(is_proxy(bp, proxy));
    int tree = bp->leaves[proxy].tree;
    remove_leaf(bp, tree, proxy);
    bp->nodes[proxy].box = box;
    insert_leaf(bp, tree, proxy); /* takes the parent node just freed: cannot fail */
    mark_moved(bp, proxy);
}

aabb bp_get_aabb(const broadphase *bp, int proxy)
{
    assert(is_proxy(bp, proxy));
    return bp->nodes[proxy].box;
}

int bp_get_user(const broadphase *bp, int proxy)
{
    assert(is_proxy(bp, proxy));
    return bp->leaves[proxy].user;
}

int bp_proxy_count(const broadphase *bp) { return bp->proxy_count; }

int bp_tree_height(const broadphase *bp, int is_static)
{
    int root = bp->root[is_static ? STATIC_TREE : MOVING_TREE];
    return root == NULL_NODE ? -1 : bp->nodes[root].height;
}

double bp_tree_area(const broadphase *bp, int is_static)
{
    /* the inner nodes are the written non-leaves; free ones have height -1 */
    int root = bp->root[is_static ? STATIC_TREE : MOVING_TREE];
    double area = 0.0;
    for (int i = 0; i < bp->fresh; i++) {
        const bp_node *n = &bp->nodes[i];
        if (n->height <= 0) continue;
        int top = i;
        while (bp->nodes[top].parent != NULL_NODE) top = bp->nodes[top].parent;
        if (top == root) area += aabb_area(n->box);
    }
    return area;
}

/* Depth-first walk with a local stack that spills to the heap for deep trees. */
typedef struct walk {
    int local[LOCAL_STACK];
    int *items;
    int count, capacity;
} walk;

static void walk_init(walk *w, int root)
{
    w->items = w->local;
    w->capacity = LOCAL_STACK;
    w->count = 0;
    if (root != NULL_NODE) w->items[w->count++] = root;
}

static void walk_free(walk *w)
{
    if (w->items != w->local) free(w->items);
}

/* Pushes two nodes. Returns 0 on out of memory (the walk then ends early). */
static int walk_push2(walk *w, int a, int b)
{
    if (w->count + 2 > w->capacity) {
        int cap = w->capacity * 2;
        int *n = w->items == w->local ? malloc(sizeof *n * (size_t)cap) : realloc(w->items, sizeof *n * (size_t)cap);
        if (!n) return 0;
        if (w->items == w->local) memcpy(n, w->local, sizeof w->local);
        w->items = n;
        w->capacity = cap;
    }
    w->items[w->count++] = a;
    w->items[w->count++] = b;
    return 1;
}

/* Reports the pairs of moved proxy q with the leaves of one tree. When both
 * proxies moved, only the lower id reports, so each pair comes once. */
static void pairs_in_tree(const broadphase *bp, int tree, int q, bp_pair_fn *fn, void *ctx)
{
    const bp_node *N = bp->nodes;
    aabb box = N[q].box;
    int user = bp->leaves[q].user;
    int root = bp->root[tree];
    if (root == NULL_NODE || !aabb_overlap(N[root].box, box)) return;
    walk w;
    walk_init(&w, root);
    /* every node on the stack overlaps the box */
    while (w.count > 0) {
        int i = w.items[--w.count];
        if (is_leaf(&N[i])) {
            if (i == q || (i < q && bp->leaves[i].move_slot >= 0)) continue;
            fn(ctx, user, bp->leaves[i].user);
            continue;
        }
        int a = N[i].child1, b = N[i].child2;
        int oa = aabb_overlap(N[a].box, box), ob = aabb_overlap(N[b].box, box);
        if (oa && ob) {
            if (!walk_push2(&w, a, b)) break;
        } else if (oa || ob) {
            w.items[w.count++] = oa ? a : b; /* room: one was just popped */
        }
    }
    walk_free(&w);
}

int bp_is_moved(const broadphase *bp, int proxy) { return bp->leaves[proxy].move_slot >= 0; }

void bp_set_moved(broadphase *bp, int proxy, int moved)
{
    if (moved) mark_moved(bp, proxy);
    else unmark_moved(bp, proxy);
}

void bp_update_pairs(broadphase *bp, bp_pair_fn *fn, void *ctx)
{
    for (int m = 0; m < bp->move_count; m++) {
        int q = bp->moved[m];
        pairs_in_tree(bp, MOVING_TREE, q, fn, ctx);
        if (bp->leaves[q].tree == MOVING_TREE) pairs_in_tree(bp, STATIC_TREE, q, fn, ctx);
    }
    for (int m = 0; m < bp->move_count; m++) bp->leaves[bp->moved[m]].move_slot = -1;
    bp->move_count = 0;
}

void bp_query(const broadphase *bp, aabb box, bp_query_fn *fn, void *ctx)
{
    const bp_node *N = bp->nodes;
    for (int tree = 0; tree < 2; tree++) {
        walk w;
        walk_init(&w, bp->root[tree]);
        int stop = 0;
        while (w.count > 0) {
            int i = w.items[--w.count];
            if (!aabb_overlap(N[i].box, box)) continue;
            if (!is_leaf(&N[i])) {
                if (!walk_push2(&w, N[i].child1, N[i].child2)) break;
                continue;
            }
            if (!fn(ctx, bp->leaves[i].user)) {
                stop = 1;
                break;
            }
        }
        walk_free(&w);
        if (stop) return;
    }
}

/* The segment o + t d, t in [0, max_t], with precomputed reciprocals; an axis
 * whose reciprocal overflows is treated as parallel (never 0 * inf = NaN). */
typedef struct ray {
    double o[3], inv[3];
    int parallel[3];
} ray;

/* Entry parameter of the segment into the box, or HUGE_VAL when it misses. */
static double ray_enter(const ray *r, aabb b, double max_t)
{
    double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    double t0 = 0.0, t1 = max_t;
    for (int k = 0; k < 3; k++) {
        if (r->parallel[k]) {
            if (r->o[k] < lo[k] || r->o[k] > hi[k]) return HUGE_VAL;
            continue;
        }
        double a = (lo[k] - r->o[k]) * r->inv[k], c = (hi[k] - r->o[k]) * r->inv[k];
        if (a > c) { double t = a; a = c; c = t; }
        if (a > t0) t0 = a;
        if (c < t1) t1 = c;
        if (t0 > t1) return HUGE_VAL;
    }
    return t0;
}

void bp_ray_cast(const broadphase *bp, vec3 origin, vec3 dir, double max_t, bp_ray_fn *fn, void *ctx)
{
    const bp_node *N = bp->nodes;
    ray r;
    double d[3] = {dir.x, dir.y, dir.z};
    r.o[0] = origin.x;
    r.o[1] = origin.y;
    r.o[2] = origin.z;
    for (int k = 0; k < 3; k++) {
        r.inv[k] = 1.0 / d[k];
        r.parallel[k] = !isfinite(r.inv[k]);
    }
    for (int tree = 0; tree < 2; tree++) {
        walk w;
        walk_init(&w, bp->root[tree]);
        while (w.count > 0) {
            int i = w.items[--w.count];
            if (ray_enter(&r, N[i].box, max_t) > max_t) continue;
            if (!is_leaf(&N[i])) {
                /* the nearer child on top, so a clipping callback prunes more */
                int a = N[i].child1, b = N[i].child2;
                if (ray_enter(&r, N[a].box, max_t) < ray_enter(&r, N[b].box, max_t)) { int t = a; a = b; b = t; }
                if (!walk_push2(&w, a, b)) break;
                continue;
            }
            double t = fn(ctx, bp->leaves[i].user, origin, dir, max_t);
            if (t < 0.0) {
                walk_free(&w);
                return;
            }
            if (t < max_t) max_t = t;
        }
        walk_free(&w);
    }
}

/* Every invariant: links, boxes equal to their children's union, heights,
 * leaf and free counts, the moved buffer. */
int bp_validate(const broadphase *bp)
{
    const bp_node *N = bp->nodes;
    int leaves = 0, internal = 0, moved = 0;
    for (int tree = 0; tree < 2; tree++) {
        int root = bp->root[tree];
        if (root == NULL_NODE) continue;
        if (N[root].parent != NULL_NODE) return 0;
        walk w;
        walk_init(&w, root);
        while (w.count > 0) {
            int i = w.items[--w.count];
            if (i < 0 || i >= bp->fresh || N[i].height < 0) { walk_free(&w); return 0; }
            if (is_leaf(&N[i])) {
                const bp_leaf *l = &bp->leaves[i];
                if (N[i].height != 0 || N[i].child2 != NULL_NODE || l->tree != tree) { walk_free(&w); return 0; }
                if (l->move_slot >= 0) {
                    if (l->move_slot >= bp->move_count || bp->moved[l->move_slot] != i) { walk_free(&w); return 0; }
                    moved++;
                }
                leaves++;
                continue;
            }
            int a = N[i].child1, b = N[i].child2;
            int ok = a >= 0 && b >= 0 && a < bp->fresh && b < bp->fresh && N[a].parent == i && N[b].parent == i &&
                     N[i].height == 1 + max_int(N[a].height, N[b].height);
            if (ok) {
                aabb u = aabb_union(N[a].box, N[b].box);
                ok = memcmp(&u, &N[i].box, sizeof u) == 0;
            }
            if (!ok || !walk_push2(&w, a, b)) { walk_free(&w); return 0; }
            internal++;
        }
        walk_free(&w);
    }
    int free_nodes = bp->capacity - bp->fresh;
    if (bp->fresh < 0 || free_nodes < 0) return 0;
    for (int list = 0; list < 2; list++)
        for (int i = list ? bp->tail_list : bp->free_list; i != NULL_NODE && free_nodes <= bp->capacity; i = N[i].parent) {
            if (i < 0 || i >= bp->fresh || N[i].height != -1) return 0;
            free_nodes++;
        }
    return leaves == bp->proxy_count && moved == bp->move_count && free_nodes == bp->free_count &&
           leaves + internal + free_nodes == bp->capacity;
}
