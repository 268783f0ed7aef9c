/* ghost.c - ghost contacts between separate static bodies. A box sliding
 * from one floor tile onto the next touches the next tile's side face (or
 * the next mesh patch's boundary edge) before its top face: a contact whose
 * normal pushes it back, though the two tiles make one flat floor. Active
 * edges cannot see this (the tiles are separate bodies), so after the
 * narrowphase each dynamic body's manifolds against static and kinematic
 * bodies are compared pairwise: manifold j is a ghost of manifold i when
 * their normals differ, j's body does not rise above the plane i touches
 * (along i's normal it reaches no farther than i's body), while along j's
 * normal i's body does reach farther than j's (so j's normal is not the
 * normal of a common surface). A ghost is left out of this step's solve;
 * the surface it lies under holds the body. A true step (a tile higher
 * than its neighbour by more than GHOST_STEP, 0.5 mm) or a wall
 * standing on the floor rises above the floor's plane and keeps its contact.
 *
 * Then the manifolds a dynamic body has with several static bodies on one
 * plane (the same normal and offset, the same mixed friction and
 * restitution) are solved as one: their points, outline corners first,
 * reduced to four, each keeping its warm-start impulses. Static bodies do
 * not move, so which one a point belongs to does not matter to the solver,
 * and a box over four tiles is then held exactly as on one plane, not by
 * sixteen points whose iterative solution twists it. */
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "world.h"
#include "ghost.h"
#include "collision.h"
#include "manifold.h"
#include "mesh.h"
#include "heightfield.h"
#include "triangle_contact.h"

/* the smallest step between tiles that is a true step (a tenth of 5 mm,
 * linear_slop's default once) */
#define GHOST_STEP 0.0005

/* how much farther i's body must reach along j's normal than j's own body
 * (the test that j's normal is no common surface's): any real protrusion,
 * not a step's height. Where two flat tiles meet, a sphere just past the
 * seam has an edge contact with the tile behind, its normal tilted by the
 * offset over the radius; the tile ahead reaches farther along it only by
 * that tilt times the tile's width (0.47 mm for 0.25 m tiles at 1.9 mrad),
 * under GHOST_STEP, so the edge contact was solved and pushed the sphere
 * on: a sphere rolling over 0.25 m tiles sped up 0.06 % and came 1.8 mm
 * off the plane's path. Where a flat tile meets one falling away, the two
 * reach equally far along the falling one's normal (its plane runs through
 * the crease), so it stays a support. */
#define GHOST_REACH_TOL 1e-6

#define GHOST_COS (1.0 - 1e-12) /* normals this close are one surface's (the reach test decides the rest) */

typedef struct ghost_entry {
    int dynamic, other;    /* id indices */
    int contact;           /* index into the contact set */
    int listed;            /* index into the touching list */
    vec3 normal;           /* from the other body towards the dynamic one */
} ghost_entry;

static int by_dynamic(const void *x, const void *y)
{
    const ghost_entry *a = x, *b = y;
    if (a->dynamic != b->dynamic) return a->dynamic < b->dynamic ? -1 : 1;
    if (a->other != b->other) return a->other < b->other ? -1 : 1; /* the same order every step */
    return a->contact < b->contact ? -1 : (a->contact > b->contact);
}

/* Sorts n entries by by_dynamic (a total order: the contacts differ), so
 * the result is the one qsort gave: runs of 16 by insertion, then bottom-up
 * merges through tmp. Inline comparisons instead of qsort's callback (62M
 * instructions on the 2000-body pile, callgrind). */
static void sort_entries(ghost_entry *a, ghost_entry *tmp, int n)
{
    enum { RUN = 16 };
    for (int lo = 0; lo < n; lo += RUN) {
        int hi = lo + RUN < n ? lo + RUN : n;
        for (int i = lo + 1; i < hi; i++) {
            if (by_dynamic(&a[i - 1], &a[i]) <= 0) continue;
            ghost_entry x = a[i];
            int j = i;
            while (j > lo && by_dynamic(&a[j - 1], &x) > 0) { a[j] = a[j - 1]; j--; }
            a[j] = x;
        }
    }
    for (int width = RUN; width < n; width *= 2) {
        for (int lo = 0; lo + width < n; lo += 2 * width) {
            int mid = lo + width, hi = lo + 2 * width < n ? lo + 2 * width : n;
            if (by_dynamic(&a[mid - 1], &a[mid]) <= 0) continue; /* already in order */
            int i = lo, j = mid, k = lo;
            while (i < mid && j < hi) tmp[k++] = by_dynamic(&a[j], &a[i]) < 0 ? a[j++] : a[i++];
            while (i < mid) tmp[k++] = a[i++];
            while (j < hi) tmp[k++] = a[j++];
            memcpy(a + lo, tmp + lo, sizeof *a * (size_t)(hi - lo));
        }
    }
}

/* Within each dynamic body's run of entries, the other bodies in rank order
 * (world_rank_cmp), not by id: which manifold removes another as a ghost and
 * which leads a merge must not depend on the order the bodies were made in
 * (docs/physics.md, "Creation order"). A run is a few entries: insertion. */
static void rank_others(const body_store *s, ghost_entry *e, int n)
{
    for (int first = 0; first < n;) {
        int last = first + 1;
        while (last < n && e[last].dynamic == e[first].dynamic) last++;
        for (int i = first + 1; i < last; i++) {
            ghost_entry x = e[i];
            int j = i;
            while (j > first && world_rank_cmp(s, s->ids[e[j - 1].other].slot, s->ids[x.other].slot) > 0) {
                e[j] = e[j - 1];
                j--;
            }
            e[j] = x;
        }
        first = last;
    }
}

/* How far the shape reaches along unit direction n: max over it of
 * dot(n, x), over the part of a mesh or height field within `near` (world
 * bounds around the dynamic body: a hill elsewhere on the same mesh does
 * not count). */
typedef struct reach_query { vec3 n; double best; } reach_query;

static int reach_visit(void *ctx, const vec3 v[3], unsigned active, uint32_t index)
{
    reach_query *q = ctx;
    (void)active; (void)index;
    for (int k = 0; k < 3; k++) q->best = dmax(q->best, v3_dot(q->n, v[k]));
    return 1;
}

static double reach_along(const shape *s, xform x, vec3 n, aabb near)
{
    if (s->type == SHAPE_PLANE) {
        vec3 pn = q_rotate(x.q, s->plane_normal);
        if (v3_dot(pn, n) < 1.0 - 1e-9) return INFINITY; /* a plane reaches without end except along its normal */
        return s->plane_offset + v3_dot(pn, x.p);
    }
    if (s->type == SHAPE_MESH || s->type == SHAPE_HEIGHTFIELD) {
        /* the world box in the shape's frame: its corners' bounds */
        aabb local = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
        for (int k = 0; k < 8; k++) {
            vec3 c = v3(k & 1 ? near.hi.x : near.lo.x, k & 2 ? near.hi.y : near.lo.y, k & 4 ? near.hi.z : near.lo.z);
            vec3 l = xf_inv_point(x, c);
            local.lo = v3_min(local.lo, l);
            local.hi = v3_max(local.hi, l);
        }
        reach_query q = {q_inv_rotate(x.q, n), -INFINITY};
        if (s->type == SHAPE_MESH) mesh_query(s->mesh, local, reach_visit, &q);
        else heightfield_query(s->field, local, reach_visit, &q);
        return q.best + v3_dot(n, x.p);
    }
    return v3_dot(n, xf_point(x, shape_support_local(s, q_inv_rotate(x.q, n))));
}

/* A contact left out of the solve: its impulses are not this step's, so
 * they must not warm-start it when it is solved again, and its manifold
 * must be recomputed. */
static void unsolved(contact_set *cs, int ci)
{
    contact_data *d = CONTACT_DATA(cs, ci);
    for (int k = 0; k < MANIFOLD_MAX_POINTS; k++) {
        d->state[k].normal_impulse = 0;
        d->state[k].tangent_impulse[0] = d->state[k].tangent_impulse[1] = 0;
    }
    cs->items[ci].flags &= ~(uint32_t)CONTACT_REUSABLE;
}

#define MERGE_COS (1.0 - 1e-9)
#define MERGE_MAX 64

/* Offset of the static surface under a manifold's first point, along n
 * (from the static body to the dynamic one): the point lies midway. */
static double surface_offset(const manifold *m, vec3 n)
{
    return v3_dot(n, m->points[0].point) - 0.5 * m->points[0].separation;
}

/* A merged manifold kept by one of its contacts: the points another
 * contact gave keep no feature id (the same id names another place on the
 * other body: identical mesh patches number their triangles alike, so a
 * patch's point matched another patch's impulse next step and a box on
 * 2 m patches of 3 x 3 cells was thrown 1 m off its path); they are
 * matched by position only. */
#define FOREIGN_ID 0xfffffff0u

static void own_ids(manifold *m, const int *owner, int contact)
{
    for (int k = 0; k < m->count; k++)
        if (owner[k] != contact) m->points[k].id = FOREIGN_ID | (uint32_t)k;
}

/* Merges, per dynamic body, the manifolds against static bodies on one plane
 * into the first of them (entries sorted by dynamic body, ghosts unlisted).
 * Returns how many manifolds were taken off the touching list. */
static int merge_coplanar(carom_world *w, ghost_entry *e, int n, double tol)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    step_scratch *sc = &w->scratch;
    int removed = 0;
    for (int first = 0; first < n;) {
        int last = first + 1;
        while (last < n && e[last].dynamic == e[first].dynamic) last++;
        for (int i = first; i < last && last - first > 1; i++) {
            if (e[i].listed < 0 || s->type[s->ids[e[i].other].slot] != CAROM_BODY_STATIC) continue;
            contact_data *di = CONTACT_DATA(cs, e[i].contact);
            if (di->m.count == 0) continue;
            double hi = surface_offset(&di->m, e[i].normal);
            manifold_point pts[MERGE_MAX];
            contact_point_state st[MERGE_MAX];
            int group[MERGE_MAX], from[MERGE_MAX]; /* from: the contact a candidate comes from */
            int np = 0, merged = 0;
            for (int k = 0; k < di->m.count; k++) { pts[np] = di->m.points[k]; st[np] = di->state[k]; from[np] = e[i].contact; np++; }
            for (int j = i + 1; j < last; j++) {
                if (e[j].listed < 0 || e[j].other == e[i].other) continue;
                if (s->type[s->ids[e[j].other].slot] != CAROM_BODY_STATIC) continue;
                contact_data *dj = CONTACT_DATA(cs, e[j].contact);
                if (dj->m.count == 0 || np + dj->m.count > MERGE_MAX) continue;
                if (v3_dot(e[i].normal, e[j].normal) < MERGE_COS) continue;
                if (dj->friction != di->friction || dj->restitution != di->restitution) continue;
                if (fabs(surface_offset(&dj->m, e[j].normal) - hi) > tol) continue;
                /* friction impulses carry over only in the same tangent basis */
                int same_basis = v3_dot(di->tangent1, dj->tangent1) > 0.999;
                for (int k = 0; k < dj->m.count; k++) {
                    pts[np] = dj->m.points[k];
                    st[np] = dj->state[k];
                    if (!same_basis) st[np].tangent_impulse[0] = st[np].tangent_impulse[1] = 0;
                    from[np] = e[j].contact;
                    np++;
                }
                sc->touching[e[j].listed] = -1;
                e[j].listed = -1;
                cs->items[e[j].contact].flags &= ~(uint32_t)CONTACT_REUSABLE;
                group[merged++] = j;
            }
            if (!merged) continue;
            removed += merged;
            /* reduce, carrying each point's state: the candidate index rides in the id */
            uint32_t ids[MERGE_MAX];
            manifold_point all[MERGE_MAX];
            for (int k = 0; k < np; k++) { all[k] = pts[k]; ids[k] = pts[k].id; pts[k].id = (uint32_t)k; }
            vec3 mn = di->m.normal;
            int c = manifold_outline(pts, np, mn);
            c = manifold_reduce_outline(pts, c, mn);
            contact_point_state kept[MANIFOLD_MAX_POINTS];
            int owner[MANIFOLD_MAX_POINTS];
            for (int k = 0; k < c; k++) {
                owner[k] = from[pts[k].id];
                /* where bodies meet, several give the same point: keep the state
                 * that carries the most (the others may be fresh) */
                int src = (int)pts[k].id;
                for (int q = 0; q < np; q++)
                    if (v3_len2(v3_sub(all[q].point, all[src].point)) < 1e-12 &&
                        fabs(st[q].normal_impulse) > fabs(st[src].normal_impulse))
                        src = q;
                kept[k] = st[src];
                pts[k].id = ids[pts[k].id];
            }
            for (int k = 0; k < c; k++) { di->m.points[k] = pts[k]; di->state[k] = kept[k]; }
            di->m.count = c;
            own_ids(&di->m, owner, e[i].contact);
            /* this step's manifold is no longer the narrowphase's own: recompute it next step */
            cs->items[e[i].contact].flags &= ~(uint32_t)CONTACT_REUSABLE;
            /* the others remember it too: whichever leads next step warm-starts
             * from it (world_share_merged_impulses gives them the solved
             * impulses; a point only another body's manifold has next step
             * would else start from this step's guess, never from a solved
             * impulse: the front corners of a box sliding onto the next tile
             * started from zero every step, and at one iteration (fast) the
             * box rocked at 1.3 mm/s vertical) */
            for (int g = 0; g < merged; g++) {
                contact_data *dj = CONTACT_DATA(cs, e[group[g]].contact);
                vec3 nj = dj->m.normal;
                dj->m = di->m;
                dj->m.normal = v3_dot(nj, mn) < 0 ? v3_neg(mn) : mn;
                for (int k = 0; k < c; k++) { dj->m.points[k].id = pts[k].id; dj->state[k] = kept[k]; }
                own_ids(&dj->m, owner, e[group[g]].contact);
                if (array_reserve((void **)&sc->merged, &sc->merged_capacity, 2 * sc->merged_count + 2, sizeof *sc->merged)) {
                    sc->merged[2 * sc->merged_count] = e[i].contact;
                    sc->merged[2 * sc->merged_count + 1] = e[group[g]].contact;
                    sc->merged_count++;
                }
            }
        }
        first = last;
    }
    return removed;
}

void world_share_merged_impulses(carom_world *w, const step_context *ctx)
{
    (void)ctx;
    const body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    step_scratch *sc = &w->scratch;
    for (int k = 0; k < sc->merged_count; k++) {
        int lead = sc->merged[2 * k], follower = sc->merged[2 * k + 1];
        const contact_data *dl = CONTACT_DATA(cs, lead);
        contact_data *df = CONTACT_DATA(cs, follower);
        const contact *cf = &cs->items[follower];
        if (df->m.count != dl->m.count) continue;
        /* the same order of bodies (the normal's sign): the friction basis
         * and its impulses carry over as they are, else only the normal's */
        int same = v3_dot(df->m.normal, dl->m.normal) > 0;
        int a = s->ids[cf->id_a].slot;
        xform xa = s->type[a] == CAROM_BODY_STATIC ? body_xform(s, a) : sc->pose[a];
        for (int i = 0; i < dl->m.count; i++) {
            /* only the follower's own points (own_ids): another body's
             * impulse kept here would warm-start this contact too, twice
             * the load where the two are solved apart next step */
            contact_point_state st = dl->state[i];
            if (df->m.points[i].id >= FOREIGN_ID) {
                st.normal_impulse = 0;
                st.tangent_impulse[0] = st.tangent_impulse[1] = 0;
            }
            if (!same) st.tangent_impulse[0] = st.tangent_impulse[1] = 0;
            st.local_a = xf_inv_point(xa, dl->m.points[i].point);
            df->state[i] = st;
        }
        if (same) df->tangent1 = dl->tangent1;
    }
    sc->merged_count = 0;
}

void world_remove_ghost_contacts(carom_world *w, const step_context *ctx)
{
    (void)ctx;
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    step_scratch *sc = &w->scratch;
    sc->merged_count = 0;
    /* the collision stage listed the touching contacts between a dynamic
     * body and a static or kinematic one (step_scratch.mixed) */
    int n = sc->mixed_count;
    if (n < 2) return;
    ghost_entry *e = malloc(sizeof *e * 2 * (size_t)n); /* the entries, then sort_entries' merge space */
    if (!e) return; /* out of memory: the ghosts stay, as they would without this pass */
    n = 0;
    for (int m = 0; m < sc->mixed_count; m++) {
        int k = sc->mixed[m];
        int ci = sc->touching[k];
        const contact *c = &cs->items[ci];
        int da = s->type[s->ids[c->id_a].slot] == CAROM_BODY_DYNAMIC;
        /* the manifold's normal points from a to b */
        vec3 normal = da ? v3_neg((CONTACT_DATA(cs, ci))->m.normal) : (CONTACT_DATA(cs, ci))->m.normal;
        ghost_entry g = {da ? c->id_a : c->id_b, da ? c->id_b : c->id_a, ci, k, normal};
        e[n++] = g;
    }
    sort_entries(e, e + n, n);
    rank_others(s, e, n);
    double tol = GHOST_STEP;
    int removed = 0;
    for (int first = 0; first < n;) {
        int last = first + 1;
        while (last < n && e[last].dynamic == e[first].dynamic) last++;
        if (last - first < 2) { first = last; continue; } /* one manifold: no pair to compare */
        int dyn = s->ids[e[first].dynamic].slot;
        aabb near = aabb_fatten(shape_aabb(&s->shapes[dyn], body_xform(s, dyn)), w->def.speculative_distance);
        for (int j = first; j < last; j++) {
            const ghost_entry *gj = &e[j];
            int sj = s->ids[gj->other].slot;
            xform xj = body_xform(s, sj);
            for (int i = first; i < last; i++) {
                const ghost_entry *gi = &e[i];
                if (i == j || gi->other == gj->other || gi->listed < 0) continue;
                if (v3_dot(gi->normal, gj->normal) >= GHOST_COS) continue;
                int si = s->ids[gi->other].slot;
                xform xi = body_xform(s, si);
                /* j's body stays under i's plane, and j's normal is not a common surface's */
                if (!(reach_along(&s->shapes[sj], xj, gi->normal, near) <=
                      reach_along(&s->shapes[si], xi, gi->normal, near) + tol))
                    continue;
                if (reach_along(&s->shapes[si], xi, gj->normal, near) <=
                    reach_along(&s->shapes[sj], xj, gj->normal, near) + GHOST_REACH_TOL)
                    continue;
                sc->touching[gj->listed] = -1;
                e[j].listed = -1;
                unsolved(cs, e[j].contact);
                removed++;
                break;
            }
        }
        first = last;
    }
    removed += merge_coplanar(w, e, n, tol);
    free(e);
    if (!removed) return;
    int kept = 0;
    for (int k = 0; k < sc->touching_count; k++)
        if (sc->touching[k] >= 0) sc->touching[kept++] = sc->touching[k];
    sc->touching_count = kept;
}
