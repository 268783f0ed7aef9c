/* broadphase.c - two dynamic AABB trees (moving and static proxies). Leaves
 * are inserted next to the sibling that least grows the tree's surface area,
 * and AVL-style rotations keep the height logarithmic. A moved-proxy buffer
 * makes pair finding incremental: only moved proxies are queried, and static
 * proxies are never queried against each other. */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "broadphase.h"

#define NULL_NODE (-1)
#define LOCAL_STACK 256

typedef struct bp_node {
    aabb box;
    int parent;     /* next free node while on the free list */
    int left, right;
    int height;     /* leaf 0, free -1 */
    int user;
    int tree;       /* 0 moving, 1 static */
    int moved;
} bp_node;

struct broadphase {
    bp_node *nodes;
    int capacity, free_list;
    int root[2];
    int *moved;
    int move_count, move_capacity;
    int proxy_count;
};

broadphase *bp_create(void)
{
    broadphase *bp = calloc(1, sizeof *bp);
    if (!bp) return NULL;
    bp->free_list = NULL_NODE;
    bp->root[0] = bp->root[1] = NULL_NODE;
    return bp;
}

void bp_destroy(broadphase *bp)
{
    if (!bp) return;
    free(bp->nodes);
    free(bp->moved);
    free(bp);
}

static int alloc_node(broadphase *bp)
{
    if (bp->free_list == NULL_NODE) {
        int cap = bp->capacity ? bp->capacity * 2 : 64;
        bp_node *n = realloc(bp->nodes, sizeof *n * (size_t)cap);
        if (!n) return NULL_NODE;
        bp->nodes = n;
        for (int i = bp->capacity; i < cap; i++) {
            n[i].parent = i + 1 < cap ? i + 1 : NULL_NODE;
            n[i].height = -1;
        }
        bp->free_list = bp->capacity;
        bp->capacity = cap;
    }
    int id = bp->free_list;
    bp_node *n = &bp->nodes[id];
    bp->free_list = n->parent;
    n->parent = n->left = n->right = NULL_NODE;
    n->height = 0;
    n->user = -1;
    n->tree = 0;
    n->moved = 0;
    return id;
}

static void free_node(broadphase *bp, int id)
{
    bp->nodes[id].parent = bp->free_list;
    bp->nodes[id].height = -1;
    bp->free_list = id;
}

/* AVL rotation at a: returns the new root of this subtree. */
static int balance(broadphase *bp, int tree, int ia)
{
    bp_node *N = bp->nodes;
    bp_node *a = &N[ia];
    if (a->left == NULL_NODE || a->height < 2) return ia;
    int ib = a->left, ic = a->right;
    int bal = N[ic].height - N[ib].height;
    if (bal > 1 || bal < -1) {
        /* promote the taller child (c when right-heavy, b when left-heavy) */
        int up = bal > 1 ? ic : ib, other = bal > 1 ? ib : ic;
        bp_node *u = &N[up];
        int iff = u->left, ig = u->right;
        u->left = ia;
        u->parent = a->parent;
        a->parent = up;
        if (u->parent != NULL_NODE) {
            if (N[u->parent].left == ia) N[u->parent].left = up;
            else N[u->parent].right = up;
        } else {
            bp->root[tree] = up;
        }
        /* the taller grandchild stays under `up`; the shorter one goes to a */
        int keep = N[iff].height > N[ig].height ? iff : ig, give = keep == iff ? ig : iff;
        u->right = keep;
        if (bal > 1) { a->right = give; a->left = other; }
        else { a->left = give; a->right = other; }
        N[give].parent = ia;
        a->box = aabb_union(N[a->left].box, N[a->right].box);
        a->height = 1 + (N[a->left].height > N[a->right].height ? N[a->left].height : N[a->right].height);
        u->box = aabb_union(a->box, N[keep].box);
        u->height = 1 + (a->height > N[keep].height ? a->height : N[keep].height);
        return up;
    }
    return ia;
}

static void refit_up(broadphase *bp, int tree, int i)
{
    bp_node *N = bp->nodes;
    while (i != NULL_NODE) {
        i = balance(bp, tree, i);
        int l = N[i].left, r = N[i].right;
        N[i].height = 1 + (N[l].height > N[r].height ? N[l].height : N[r].height);
        N[i].box = aabb_union(N[l].box, N[r].box);
        i = N[i].parent;
    }
}

static int insert_leaf(broadphase *bp, int tree, int leaf)
{
    bp_node *N = bp->nodes;
    if (bp->root[tree] == NULL_NODE) {
        bp->root[tree] = leaf;
        N[leaf].parent = NULL_NODE;
        return 1;
    }
    aabb box = N[leaf].box;
    int i = bp->root[tree];
    while (N[i].left != NULL_NODE) {
        int l = N[i].left, r = N[i].right;
        double area = aabb_area(N[i].box);
        double combined = aabb_area(aabb_union(N[i].box, box));
        double cost = 2.0 * combined, inherit = 2.0 * (combined - area);
        double cl = aabb_area(aabb_union(N[l].box, box)) + inherit;
        double cr = aabb_area(aabb_union(N[r].box, box)) + inherit;
        if (N[l].left != NULL_NODE) cl -= aabb_area(N[l].box);
        if (N[r].left != NULL_NODE) cr -= aabb_area(N[r].box);
        if (cost < cl && cost < cr) break;
        i = cl < cr ? l : r;
    }
    int parent = alloc_node(bp);
    if (parent == NULL_NODE) return 0;
    N = bp->nodes; /* may have moved */
    int old_parent = N[i].parent;
    N[parent].parent = old_parent;
    N[parent].box = aabb_union(box, N[i].box);
    N[parent].height = N[i].height + 1;
    N[parent].left = i;
    N[parent].right = leaf;
    N[parent].tree = tree;
    N[i].parent = parent;
    N[leaf].parent = parent;
    if (old_parent != NULL_NODE) {
        if (N[old_parent].left == i) N[old_parent].left = parent;
        else N[old_parent].right = parent;
    } else {
        bp->root[tree] = parent;
    }
    refit_up(bp, tree, N[leaf].parent);
    return 1;
}

static void remove_leaf(broadphase *bp, int tree, int leaf)
{
    bp_node *N = bp->nodes;
    if (leaf == bp->root[tree]) {
        bp->root[tree] = NULL_NODE;
        return;
    }
    int parent = N[leaf].parent, grand = N[parent].parent;
    int sibling = N[parent].left == leaf ? N[parent].right : N[parent].left;
    if (grand != NULL_NODE) {
        if (N[grand].left == parent) N[grand].left = sibling;
        else N[grand].right = sibling;
        N[sibling].parent = grand;
        free_node(bp, parent);
        refit_up(bp, tree, grand);
    } else {
        bp->root[tree] = sibling;
        N[sibling].parent = NULL_NODE;
        free_node(bp, parent);
    }
}

static int mark_moved(broadphase *bp, int proxy)
{
    if (bp->nodes[proxy].moved) return 1;
    if (!array_reserve((void **)&bp->moved, &bp->move_capacity, bp->move_count + 1, sizeof *bp->moved)) return 0;
    bp->moved[bp->move_count++] = proxy;
    bp->nodes[proxy].moved = 1;
    return 1;
}

int bp_create_proxy(broadphase *bp, aabb box, int is_static, int user)
{
    /* reserve the move-buffer slot and the parent node first, so failure leaves no trace */
    if (!array_reserve((void **)&bp->moved, &bp->move_capacity, bp->move_count + 1, sizeof *bp->moved)) return -1;
    int leaf = alloc_node(bp);
    if (leaf == NULL_NODE) return -1;
    int spare = alloc_node(bp);
    if (spare == NULL_NODE) { free_node(bp, leaf); return -1; }
    free_node(bp, spare);
    int tree = is_static ? 1 : 0;
    bp_node *n = &bp->nodes[leaf];
    n->box = box;
    n->user = user;
    n->tree = tree;
    insert_leaf(bp, tree, leaf);
    mark_moved(bp, leaf);
    bp->proxy_count++;
    return leaf;
}

void bp_destroy_proxy(broadphase *bp, int proxy)
{
    bp_node *n = &bp->nodes[proxy];
    if (n->moved) {
        for (int i = 0; i < bp->move_count; i++)
            if (bp->moved[i] == proxy) bp->moved[i] = NULL_NODE;
    }
    remove_leaf(bp, n->tree, proxy);
    free_node(bp, proxy);
    bp->proxy_count--;
}

void bp_move_proxy(broadphase *bp, int proxy, aabb box)
{
    int tree = bp->nodes[proxy].tree;
    remove_leaf(bp, tree, proxy);
    bp->nodes[proxy].box = box;
    insert_leaf(bp, tree, proxy); /* reuses the freed parent node: cannot fail */
    mark_moved(bp, proxy);
}

aabb bp_get_aabb(const broadphase *bp, int proxy) { return bp->nodes[proxy].box; }
int bp_get_user(const broadphase *bp, int proxy) { return bp->nodes[proxy].user; }
int bp_proxy_count(const broadphase *bp) { return bp->proxy_count; }

/* Depth-first walk with a local stack that spills to the heap for deep trees. */
typedef struct walk {
    int local[LOCAL_STACK];
    int *items;
    int count, capacity;
} walk;

static void walk_init(walk *w) { w->items = w->local; w->count = 0; w->capacity = LOCAL_STACK; }
static void walk_free(walk *w) { if (w->items != w->local) free(w->items); }
static int walk_push(walk *w, int v)
{
    if (w->count == w->capacity) {
        int cap = w->capacity * 2;
        int *n = w->items == w->local ? malloc(sizeof *n * (size_t)cap) : realloc(w->items, sizeof *n * (size_t)cap);
        if (!n) return 0;
        if (w->items == w->local) memcpy(n, w->local, sizeof w->local);
        w->items = n;
        w->capacity = cap;
    }
    w->items[w->count++] = v;
    return 1;
}

typedef struct pair_ctx {
    broadphase *bp;
    int self;
    bp_pair_fn *fn;
    void *ctx;
} pair_ctx;

static void query_tree(const broadphase *bp, int tree, aabb box, int self, pair_ctx *pc, bp_query_fn *qfn, void *qctx,
                       int *stop)
{
    walk w;
    walk_init(&w);
    if (bp->root[tree] != NULL_NODE) walk_push(&w, bp->root[tree]);
    const bp_node *N = bp->nodes;
    while (w.count > 0 && !*stop) {
        int i = w.items[--w.count];
        if (!aabb_overlap(N[i].box, box)) continue;
        if (N[i].left != NULL_NODE) {
            if (!walk_push(&w, N[i].left) || !walk_push(&w, N[i].right)) break;
            continue;
        }
        if (pc) {
            if (i == self) continue;
            /* both moved: report once, from the lower proxy */
            if (N[i].moved && i < self) continue;
            pc->fn(pc->ctx, N[self].user, N[i].user);
        } else if (!qfn(qctx, N[i].user)) {
            *stop = 1;
        }
    }
    walk_free(&w);
}

void bp_update_pairs(broadphase *bp, bp_pair_fn *fn, void *ctx)
{
    for (int m = 0; m < bp->move_count; m++) {
        int q = bp->moved[m];
        if (q == NULL_NODE) continue;
        pair_ctx pc = {bp, q, fn, ctx};
        int stop = 0;
        query_tree(bp, 0, bp->nodes[q].box, q, &pc, NULL, NULL, &stop);
        if (bp->nodes[q].tree == 0) query_tree(bp, 1, bp->nodes[q].box, q, &pc, NULL, NULL, &stop);
    }
    for (int m = 0; m < bp->move_count; m++)
        if (bp->moved[m] != NULL_NODE) bp->nodes[bp->moved[m]].moved = 0;
    bp->move_count = 0;
}

void bp_query(const broadphase *bp, aabb box, bp_query_fn *fn, void *ctx)
{
    int stop = 0;
    query_tree(bp, 0, box, NULL_NODE, NULL, fn, ctx, &stop);
    if (!stop) query_tree(bp, 1, box, NULL_NODE, NULL, fn, ctx, &stop);
}

/* Entry parameter of the segment o + t d, t in [0, max_t], into box (or > max_t). */
static double ray_box(aabb b, vec3 o, vec3 d, double max_t)
{
    double t0 = 0.0, t1 = max_t;
    double os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z};
    double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    for (int i = 0; i < 3; i++) {
        if (ds[i] == 0.0) {
            if (os[i] < lo[i] || os[i] > hi[i]) return max_t + 1.0;
            continue;
        }
        double inv = 1.0 / ds[i];
        double a = (lo[i] - os[i]) * inv, c = (hi[i] - os[i]) * inv;
        if (a > c) { double t = a; a = c; c = t; }
        if (a > t0) t0 = a;
        if (c < t1) t1 = c;
        if (t0 > t1) return max_t + 1.0;
    }
    return t0;
}

void bp_ray_cast(const broadphase *bp, vec3 origin, vec3 dir, double max_t, bp_ray_fn *fn, void *ctx)
{
    const bp_node *N = bp->nodes;
    for (int tree = 0; tree < 2; tree++) {
        walk w;
        walk_init(&w);
        if (bp->root[tree] != NULL_NODE) walk_push(&w, bp->root[tree]);
        while (w.count > 0) {
            int i = w.items[--w.count];
            if (ray_box(N[i].box, origin, dir, max_t) > max_t) continue;
            if (N[i].left != NULL_NODE) {
                if (!walk_push(&w, N[i].left) || !walk_push(&w, N[i].right)) break;
                continue;
            }
            double t = fn(ctx, N[i].user, origin, dir, max_t);
            if (t < 0) { walk_free(&w); return; }
            if (t < max_t) max_t = t;
        }
        walk_free(&w);
    }
}
