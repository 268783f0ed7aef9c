/* collision.c - the collision stage of the step: broadphase pair updates feed
 * the contact cache; the narrowphase refreshes every live contact's manifold
 * and raises begin/end events. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "array.h"
#include "filter.h"
#include "world.h"
#include "material.h"
#include "collision.h"
#include "events.h"
#include "tasks.h"
#include "triangle_contact.h"
#include "compound.h"

/* The broadphase reports pairs in the order its trees hold them, which
 * depends on their history; the pairs are added in the order of the rule
 * below instead, so the contact order (and the solver's) depends on the
 * bodies alone and a world restored from a snapshot, its trees rebuilt,
 * continues bit for bit. */
static void collect_pair(void *ctx, int ida, int idb)
{
    carom_world *w = ctx;
    step_scratch *sc = &w->scratch;
    if (ida == idb) return;
    if (!array_reserve((void **)&sc->new_pairs, &sc->new_pair_capacity, sc->new_pair_count + 1, sizeof *sc->new_pairs))
        return; /* out of memory: the pair is retried when a proxy moves again */
    uint32_t lo = (uint32_t)(ida < idb ? ida : idb), hi = (uint32_t)(ida < idb ? idb : ida);
    sc->new_pairs[sc->new_pair_count++] = ((uint64_t)lo << 32) | hi;
}

/* Which body of a new pair is the solve's body A (the normal points from A
 * to B, A's frame holds the points' anchors and the friction basis), and the
 * order new pairs are added to the contact set in, come from the bodies, never
 * from their ids: a scene then moves the same, to the bit, whatever order
 * its bodies were made in (issue #16; docs/physics.md 1.1, "Creation order"). A
 * body ranks before another by, in turn:
 *   1. its type: static, then kinematic, then dynamic (a floor is always A;
 *      a box made before its floor of tiles stopped about 1 mm farther as A);
 *   2. its shape kind (carom_shape_type's order: sphere, box, capsule, ...);
 *   3. its centre of mass when the pair is made: lower z, then y, then x;
 *   4. its orientation then: w, x, y, z;
 * and only two bodies equal in all four (one type and shape kind, the same
 * centre and orientation to the bit: bodies made inside each other) fall
 * back to their ids, the one tie the documentation names. -0 and +0 are
 * equal; a NaN centre (a world the NaN guard resets) compares as equal too
 * and falls through to the id. Negative: a before b. */
static inline int rank_cmp(const body_store *s, int a, int b)
{
    if (s->type[a] != s->type[b]) return s->type[a] < s->type[b] ? -1 : 1;
    if (s->shapes[a].type != s->shapes[b].type) return s->shapes[a].type < s->shapes[b].type ? -1 : 1;
    vec3 ca = s->center[a], cb = s->center[b];
    if (ca.z < cb.z) return -1;
    if (ca.z > cb.z) return 1;
    if (ca.y < cb.y) return -1;
    if (ca.y > cb.y) return 1;
    if (ca.x < cb.x) return -1;
    if (ca.x > cb.x) return 1;
    quat qa = s->rotation[a], qb = s->rotation[b];
    const double ka[4] = {qa.w, qa.x, qa.y, qa.z}, kb[4] = {qb.w, qb.x, qb.y, qb.z};
    for (int k = 0; k < 4; k++) {
        if (ka[k] < kb[k]) return -1;
        if (ka[k] > kb[k]) return 1;
    }
    int ia = s->id_index[a], ib = s->id_index[b];
    return (ia > ib) - (ia < ib);
}

int world_rank_cmp(const body_store *s, int a, int b) { return rank_cmp(s, a, b); }

void world_rank_sort(const body_store *s, int *slots, int *tmp, int n)
{
    enum { RUN = 16 };
    for (int lo = 0; lo < n; lo += RUN) {
        int hi = lo + RUN < n ? lo + RUN : n;
        for (int i = lo + 1; i < hi; i++) {
            int x = slots[i], j = i;
            while (j > lo && rank_cmp(s, slots[j - 1], x) > 0) { slots[j] = slots[j - 1]; j--; }
            slots[j] = x;
        }
    }
    for (int width = RUN; width < n; width *= 2) {
        for (int lo = 0; lo + width < n; lo += 2 * width) {
            int mid = lo + width, hi = lo + 2 * width < n ? lo + 2 * width : n;
            if (rank_cmp(s, slots[mid - 1], slots[mid]) <= 0) continue;
            int i = lo, j = mid, k = lo;
            while (i < mid && j < hi) tmp[k++] = rank_cmp(s, slots[j], slots[i]) < 0 ? slots[j++] : slots[i++];
            while (i < mid) tmp[k++] = slots[i++];
            while (j < hi) tmp[k++] = slots[j++];
            memcpy(slots + lo, tmp + lo, sizeof *slots * (size_t)(hi - lo));
        }
    }
}

/* Ranked pairs of slots (A's slot << 32 | B's slot) in order: by A's rank,
 * then B's (a total order: equal keys are one pair, reported twice). */
static inline int pair_cmp(const body_store *s, uint64_t x, uint64_t y)
{
    if (x == y) return 0;
    int c = rank_cmp(s, (int)(x >> 32), (int)(y >> 32));
    return c ? c : rank_cmp(s, (int)(x & 0xffffffffu), (int)(y & 0xffffffffu));
}

/* Sorts n ranked pair keys by pair_cmp (a total order, so the result does
 * not depend on the order the broadphase gave): runs of 16 by insertion,
 * then bottom-up merges through tmp, skipping a merge whose halves are
 * already in order; without tmp (out of memory), one insertion run. */
static void sort_pairs(const body_store *s, uint64_t *a, uint64_t *tmp, int n)
{
    const int RUN = tmp ? 16 : n;
    for (int lo = 0; lo < n; lo += RUN) {
        int hi = lo + RUN < n ? lo + RUN : n;
        for (int i = lo + 1; i < hi; i++) {
            uint64_t x = a[i];
            int j = i;
            while (j > lo && pair_cmp(s, a[j - 1], x) > 0) { a[j] = a[j - 1]; j--; }
            a[j] = x;
        }
    }
    for (int width = RUN; width < n; width *= 2) {
        for (int lo = 0; lo + width < n; lo += 2 * width) {
            int mid = lo + width, hi = lo + 2 * width < n ? lo + 2 * width : n;
            if (pair_cmp(s, a[mid - 1], a[mid]) <= 0) continue; /* already in order */
            int i = lo, j = mid, k = lo;
            while (i < mid && j < hi) tmp[k++] = pair_cmp(s, a[j], a[i]) < 0 ? a[j++] : a[i++];
            while (i < mid) tmp[k++] = a[i++];
            while (j < hi) tmp[k++] = a[j++];
            memcpy(a + lo, tmp + lo, sizeof *a * (size_t)(hi - lo));
        }
    }
}

static void add_pair(carom_world *w, int ida, int idb)
{
    body_store *s = &w->bodies;
    int sa = s->ids[ida].slot, sb = s->ids[idb].slot;
    if (sa < 0 || sb < 0 || ida == idb) return;
    if (s->type[sa] != CAROM_BODY_DYNAMIC && s->type[sb] != CAROM_BODY_DYNAMIC) return;
    if ((s->flags[sa] | s->flags[sb]) & BODY_SENSOR) return; /* sensors touch nothing (sensor.c) */
    if (!filter_bits_allow(s, sa, sb) || contact_find(&w->contacts, ida, idb) >= 0) return;
    if (w->pair_filter && !w->pair_filter(w->pair_filter_context, world_make_id(w, ida), world_make_id(w, idb))) return;
    int ci = contact_add(&w->contacts, ida, idb);
    if (ci < 0) return; /* out of memory: the pair is retried when a proxy moves again */
    material_mix_contact(w, ci);
}

/* Bodies per range handed to the task hooks. */
#define BODY_MIN_RANGE 256

typedef struct refit_job {
    carom_world *w;
    const step_context *ctx;
    unsigned char *refit; /* NULL: move each proxy here (one range, in slot order) */
} refit_job;

/* Each awake body's frame, tight bounds, look-ahead and, where those left
 * its fat bounds, new fat bounds; refit[i] says which proxies must move.
 * The moves change the broadphase tree, so on several workers they are made
 * afterwards, in slot order, on the calling thread: the same tree as one
 * worker's. */
static void refit_bodies_range(int begin, int end, int worker, void *p)
{
    const refit_job *j = p;
    carom_world *w = j->w;
    body_store *s = &w->bodies;
    step_scratch *sc = &w->scratch;
    double dt = j->ctx->dt;
    vec3 gravity = j->ctx->gravity;
    (void)worker;
    for (int i = begin; i < end; i++) {
        look_ahead *la = &sc->ahead[i];
        if (s->type[i] == CAROM_BODY_STATIC || !(s->flags[i] & BODY_AWAKE)) {
            la->velocity = v3_zero();
            la->turn = 0.0;
            if (j->refit) j->refit[i] = 0;
            continue;
        }
        /* the frame and tight bounds once per body, for every pair it is in */
        sc->pose[i] = s->collided[i] = body_xform(s, i);
        sc->tight_box[i] = shape_aabb(&s->shapes[i], sc->pose[i]);
        /* a falling body ends the step faster than it began (at dt 1/15 by
         * 4.4 cm a step), and a spinning one sweeps its corners by its turn:
         * a capsule at 25 rad/s turns its end 15 cm a step at 60 Hz, where a
         * look-ahead of its fall alone saw 8.5 cm, and it ended 4.8 cm deep */
        la->velocity = s->velocity[i];
        if (s->type[i] == CAROM_BODY_DYNAMIC) la->velocity = v3_madd(la->velocity, dt * s->gravity_scale[i], gravity);
        la->turn = v3_len(s->angular_velocity[i]) * dt * (shape_bounding_radius(&s->shapes[i]) + v3_len(s->local_center[i]));
        if (!(la->turn < INFINITY)) la->turn = 0.0; /* NaN: the step's guard resets the body */
        aabb box = aabb_fatten(sc->tight_box[i], w->def.speculative_distance + la->turn);
        /* bullets and fast bodies: the box covers this step's travel so their
         * speculative contacts exist before they arrive */
        vec3 travel = v3_scale(la->velocity, dt);
        if (v3_len2(travel) > 0.25 * WORLD_AABB_MARGIN * WORLD_AABB_MARGIN) {
            box.lo = v3_min(box.lo, v3_add(box.lo, travel));
            box.hi = v3_max(box.hi, v3_add(box.hi, travel));
        }
        int refit = !aabb_contains(s->fat_box[i], box);
        if (refit) s->fat_box[i] = aabb_fatten(box, WORLD_AABB_MARGIN);
        if (j->refit) j->refit[i] = (unsigned char)refit;
        else if (refit) bp_move_proxy(w->bp, s->proxy[i], s->fat_box[i]);
    }
}

int world_update_pairs(carom_world *w, const step_context *ctx)
{
    body_store *s = &w->bodies;
    step_scratch *sc = &w->scratch;
    if (!array_reserve_near((void **)&sc->tight_box, &sc->slot_capacity, s->count, sizeof *sc->tight_box)) return 0;
    /* the pose array shares the capacity: grow it to match */
    int cap = sc->slot_capacity;
    void *grown = realloc(sc->pose, sizeof *sc->pose * (size_t)(cap > 0 ? cap : 1));
    if (!grown) return 0;
    sc->pose = grown;
    grown = realloc(sc->ahead, sizeof *sc->ahead * (size_t)(cap > 0 ? cap : 1));
    if (!grown) return 0;
    sc->ahead = grown;
    int workers = tasks_workers(&w->def);
    if (workers > 1) {
        grown = realloc(sc->refit, (size_t)(cap > 0 ? cap : 1));
        if (!grown) return 0;
        sc->refit = grown;
    }
    refit_job job = {w, ctx, workers > 1 ? sc->refit : NULL};
    if (workers > 1) {
        tasks_run(&w->def, s->count, BODY_MIN_RANGE, refit_bodies_range, &job);
        for (int i = 0; i < s->count; i++)
            if (sc->refit[i]) bp_move_proxy(w->bp, s->proxy[i], s->fat_box[i]);
    } else {
        refit_bodies_range(0, s->count, 0, &job);
    }
    sc->new_pair_count = 0;
    bp_update_pairs(w->bp, collect_pair, w);
    /* the pairs not in the cache yet (a moved proxy reports every pair it
     * overlaps), as slots with body A first by rank */
    int np = 0;
    for (int i = 0; i < sc->new_pair_count; i++) {
        uint64_t k = sc->new_pairs[i];
        int ida = (int)(k >> 32), idb = (int)(k & 0xffffffffu);
        int sa = s->ids[ida].slot, sb = s->ids[idb].slot;
        if (sa < 0 || sb < 0 || (s->type[sa] != CAROM_BODY_DYNAMIC && s->type[sb] != CAROM_BODY_DYNAMIC) ||
            contact_find(&w->contacts, ida, idb) >= 0)
            continue;
        if (rank_cmp(s, sa, sb) > 0) { int t = sa; sa = sb; sb = t; }
        sc->new_pairs[np++] = (uint64_t)(uint32_t)sa << 32 | (uint32_t)sb;
    }
    sc->new_pair_count = np;
    /* the merge space after the keys; without it (out of memory) insertion */
    if (np > 1) {
        int room = array_reserve_near((void **)&sc->new_pairs, &sc->new_pair_capacity, 2 * np, sizeof *sc->new_pairs);
        sort_pairs(s, sc->new_pairs, room ? sc->new_pairs + np : NULL, np);
    }
    /* back to ids before any is added: the pair filter is the user's code */
    for (int i = 0; i < np; i++) {
        uint64_t k = sc->new_pairs[i];
        sc->new_pairs[i] = (uint64_t)(uint32_t)s->id_index[k >> 32] << 32 | (uint32_t)s->id_index[k & 0xffffffffu];
    }
    for (int i = 0; i < np; i++)
        add_pair(w, (int)(sc->new_pairs[i] >> 32), (int)(sc->new_pairs[i] & 0xffffffffu));
    return 1;
}

/* B's frame expressed in A's. */
static xform relative_pose(const xform *xa, const xform *xb)
{
    xform r = {xf_inv_point(*xa, xb->p), q_mul(q_conj(xa->q), xb->q)};
    return r;
}

/* A round shape's radius of curvature (its radius); 0 for shapes whose
 * contacts lie on faces, edges and corners. */
static double round_radius(const shape *s)
{
    const unsigned round = 1u << SHAPE_SPHERE | 1u << SHAPE_CAPSULE | 1u << SHAPE_CYLINDER;
    return (unsigned)s->type < 32 && (round >> s->type & 1u) ? s->radius : 0.0;
}

/* Keeps last manifold when B's material at every contact point has moved less
 * than `reuse` relative to A since the manifold was computed (a resting pair
 * moves micrometres a step): each separation changes by the normal component
 * of that motion, exact to first order, the point by half of it. now: B's
 * frame in A's (relative_pose); sa, sb: the two shapes. Returns 1 when the
 * manifold was kept. */
static int reuse_manifold(const contact *c, contact_data *d, const xform *xa, const xform *now, double reuse,
                          const shape *sa, const shape *sb)
{
    if (!(c->flags & CONTACT_REUSABLE) || d->m.count == 0 || !(reuse > 0)) return 0;
    if (v3_len2(v3_sub(now->p, c->rel_pose.p)) > reuse * reuse) return 0;
    /* B's motion in A's frame since then, x -> R x + t, as a matrix: one
     * product per point instead of two quaternion rotations */
    quat dq = q_mul(now->q, q_conj(c->rel_pose.q));
    /* A round shape rolling on the other has no motion at its contact point
     * (rolling: the two materials there move together), yet its contact moves
     * along its surface by the radius times the turn: a sphere created
     * before the plane it rolls on (the sphere A), whose path crossed the
     * line through the plane's origin along its axis, kept its manifold
     * while the old contact point rose and went behind, and sank 6 mm and sped up
     * 9 % at fast. So the chord of the turn about axes across the normal at the
     * round shape's radius (its radius of curvature), 2 r sin(angle / 2),
     * must stay within `reuse` too; a turn about the normal moves no round
     * contact along its surface (and the points off its axis are tested below). */
    double round = dmax(round_radius(sa), round_radius(sb));
    if (round > 0) {
        vec3 axis = v3(dq.x, dq.y, dq.z); /* sin(angle / 2) times the turn's axis, in A's frame */
        vec3 rolling = v3_sub(axis, v3_scale(d->normal_a, v3_dot(axis, d->normal_a)));
        if (4.0 * round * round * v3_len2(rolling) > reuse * reuse) return 0;
    }
    mat3 R = m3_from_quat(dq);
    vec3 t = v3_sub(now->p, q_rotate(dq, c->rel_pose.p));
    vec3 moved[MANIFOLD_MAX_POINTS];
    for (int i = 0; i < d->m.count; i++) {
        vec3 then = d->state[i].local_a; /* B's material there moves to R then + t */
        moved[i] = v3_sub(v3_add(m3_mulv(R, then), t), then);
        if (!(v3_len2(moved[i]) <= reuse * reuse)) return 0;
    }
    d->m.normal = q_rotate(xa->q, d->normal_a);
    for (int i = 0; i < d->m.count; i++) {
        d->m.points[i].separation = d->state[i].separation + v3_dot(d->normal_a, moved[i]);
        d->m.points[i].point = xf_point(*xa, v3_madd(d->state[i].local_a, 0.5, moved[i]));
    }
    return 1;
}

/* Largest distance any point of B can have moved relative to A since
 * rel_pose: B's origin's travel plus the chord of B's rotation at its reach. */
static double travel_bound(const contact *c, const xform *now)
{
    quat q0 = c->rel_pose.q, q1 = now->q;
    double d = q0.w * q1.w + q0.x * q1.x + q0.y * q1.y + q0.z * q1.z;
    return v3_len(v3_sub(now->p, c->rel_pose.p)) + 2.0 * c->reach_b * sqrt(dmax(0.0, 1.0 - d * d));
}

/* A pair found apart by more than the look-ahead stays apart (no narrowphase)
 * while the motion since cannot have closed the gap down to the look-ahead.
 * now: B's frame in A's. */
static int still_apart(const contact *c, const xform *now, double spec)
{
    if (!(c->flags & CONTACT_APART)) return 0;
    return travel_bound(c, now) < c->gap - spec;
}

/* Records the pose a freshly computed manifold belongs to (see reuse_manifold,
 * still_apart). An empty one stores the separation of the two shapes along
 * its normal, a lower bound on their distance. now: B's frame in A's. */
static void remember_pose(contact *c, contact_data *d, const manifold *m, const shape *sa, xform xa, const shape *sb,
                          xform xb, double spec, const xform *now)
{
    c->flags &= ~(uint32_t)(CONTACT_REUSABLE | CONTACT_APART);
    if (m->count == 0) {
        if (sa->type == SHAPE_PLANE || sb->type == SHAPE_PLANE) return; /* cheap anyway; no finite reach */
        vec3 n = m->normal;
        vec3 top_a = xf_point(xa, shape_support_local(sa, q_inv_rotate(xa.q, n)));
        vec3 low_b = xf_point(xb, shape_support_local(sb, q_inv_rotate(xb.q, v3_neg(n))));
        double gap = v3_dot(n, v3_sub(low_b, top_a));
        if (!(gap > spec) || !isfinite(gap)) return;
        c->rel_pose = *now;
        c->gap = gap;
        c->reach_b = shape_bounding_radius(sb);
        c->flags |= CONTACT_APART;
        return;
    }
    c->rel_pose = *now;
    d->normal_a = q_inv_rotate(xa.q, d->m.normal);
    for (int i = 0; i < d->m.count; i++) d->state[i].separation = d->m.points[i].separation;
    c->flags |= CONTACT_REUSABLE;
}

/* A pair with a mesh, height field or compound: its manifolds go to the
 * pair's contact (sub 0) and its extra contacts (sub 1..). A child pair owns
 * the subs base .. base + 3 (see collide_multi); within them each manifold
 * goes to the contact whose last normal is nearest, so warm starting follows
 * it. near: the bounds are within the look-ahead (else every manifold
 * empties). Returns 1 when any manifold has points. Out of memory drops the
 * manifolds that found no contact. */
static int collide_composite_pair(carom_world *w, int ci, xform xa, xform xb, double spec, int near)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    int id_a = cs->items[ci].id_a, id_b = cs->items[ci].id_b;
    int a = s->ids[id_a].slot, b = s->ids[id_b].slot;
    const shape *sha = &s->shapes[a], *shb = &s->shapes[b];
    manifold found[PAIR_MAX_MANIFOLDS];
    uint32_t base[PAIR_MAX_MANIFOLDS], sub_of[PAIR_MAX_MANIFOLDS];
    int n = near ? collide_multi(sha, xa, shb, xb, spec, found, base, PAIR_MAX_MANIFOLDS) : 0;
    /* the subs of each child pair, by normal */
    for (int j0 = 0; j0 < n;) {
        int j1 = j0 + 1;
        while (j1 < n && base[j1] == base[j0]) j1++;
        int index[COMPOSITE_MAX_MANIFOLDS], taken[COMPOSITE_MAX_MANIFOLDS] = {0, 0, 0, 0};
        for (int k = 0; k < COMPOSITE_MAX_MANIFOLDS; k++)
            index[k] = base[j0] + (uint32_t)k == 0 ? ci : contact_find_sub(cs, id_a, id_b, base[j0] + (uint32_t)k);
        for (int j = j0; j < j1; j++) {
            int best = -1;
            double best_dot = 0.9;
            for (int k = 0; k < COMPOSITE_MAX_MANIFOLDS; k++) {
                if (taken[k] || index[k] < 0 || (CONTACT_DATA(cs, index[k]))->m.count == 0) continue;
                double d = v3_dot((CONTACT_DATA(cs, index[k]))->m.normal, found[j].normal);
                if (d > best_dot) { best_dot = d; best = k; }
            }
            for (int k = 0; best < 0 && k < COMPOSITE_MAX_MANIFOLDS; k++)
                if (!taken[k] && (index[k] < 0 || (CONTACT_DATA(cs, index[k]))->m.count == 0)) best = k;
            if (best < 0) best = 0; /* cannot happen: at most COMPOSITE_MAX_MANIFOLDS per child pair */
            taken[best] = 1;
            sub_of[j] = base[j0] + (uint32_t)best;
        }
        j0 = j1;
    }
    int any = 0;
    /* this step's manifolds into their contacts */
    for (int j = 0; j < n; j++) {
        uint32_t sub = sub_of[j];
        int k = sub == 0 ? ci : contact_find_sub(cs, id_a, id_b, sub);
        if (k < 0) {
            k = contact_add_sub(cs, id_a, id_b, sub);
            if (k < 0) continue;
            if (sub + 1 > cs->items[ci].sub_limit) cs->items[ci].sub_limit = sub + 1;
        }
        if (!contact_data_alloc(cs, k)) continue; /* out of memory: the manifold is dropped */
        contact *c = &cs->items[k];
        contact_data *d = CONTACT_DATA(cs, k);
        material_mix_contact(w, k);
        manifold old_m = d->m;
        contact_point_state old_state[MANIFOLD_MAX_POINTS];
        memcpy(old_state, d->state, sizeof old_state);
        d->m = found[j];
        contact_match_points(d, &old_m, old_state, xa);
        any = 1;
        int was = (c->flags & CONTACT_TOUCHING) != 0;
        c->flags = (c->flags & ~(uint32_t)(CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_REUSABLE | CONTACT_APART)) |
                   CONTACT_TOUCHING | (was ? CONTACT_WAS_TOUCHING : 0) | CONTACT_SIM;
    }
    /* the pair's other contacts found nothing this step */
    for (uint32_t sub = 0; sub < (cs->items[ci].sub_limit > 0 ? cs->items[ci].sub_limit : 1); sub++) {
        int used = 0;
        for (int j = 0; j < n && !used; j++) used = sub_of[j] == sub;
        if (used) continue;
        int k = sub == 0 ? ci : contact_find_sub(cs, id_a, id_b, sub);
        if (k < 0) continue;
        contact *c = &cs->items[k];
        if (c->slot) CONTACT_DATA(cs, k)->m.count = 0;
        int was = (c->flags & CONTACT_TOUCHING) != 0;
        c->flags = (c->flags & ~(uint32_t)(CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_REUSABLE | CONTACT_APART)) |
                   (was ? CONTACT_WAS_TOUCHING : 0) | CONTACT_SIM;
    }
    return any;
}

/* Wakes a sleeping body during the collision stage; its later pairs read
 * this step's frame and bounds like every awake body's. */
static void wake_for_step(carom_world *w, int slot)
{
    body_store *s = &w->bodies;
    world_wake_body(w, slot);
    if (s->type[slot] == CAROM_BODY_STATIC) return;
    w->scratch.pose[slot] = body_xform(s, slot);
    w->scratch.tight_box[slot] = shape_aabb(&s->shapes[slot], w->scratch.pose[slot]);
}

/* Lists contact i (bodies at slots a, b) as touching this step, and among
 * the mixed ones when one body is dynamic and the other not. The caller
 * reserved both lists. */
static int pair_is_mixed(const body_store *s, int a, int b)
{
    return (s->type[a] == CAROM_BODY_DYNAMIC) != (s->type[b] == CAROM_BODY_DYNAMIC);
}

static void list_touching_as(step_scratch *sc, int i, int mixed)
{
    if (mixed) sc->mixed[sc->mixed_count++] = sc->touching_count;
    sc->touching[sc->touching_count++] = i;
}

static void list_touching(step_scratch *sc, const body_store *s, int i, int a, int b)
{
    list_touching_as(sc, i, pair_is_mixed(s, a, b));
}

static int body_awake(const body_store *s, int slot)
{
    return s->type[slot] != CAROM_BODY_STATIC && (s->flags[slot] & BODY_AWAKE);
}

/* The look-ahead of a pair: a fast pair looks ahead by its closing travel
 * this step. The square root only where the travel can exceed the
 * speculative distance (below 0.9 of it in squares, far outside round-off). */
/* Inlined into every caller: narrow_contact runs for every pair whose fat
 * bounds overlap (8.8M times in the 2,000-body pile's 600 steps), and the
 * calls were ~10 % of the collision stage's instructions. */
#define COLLIDE_INLINE static inline __attribute__((always_inline))

COLLIDE_INLINE double look_ahead_of(const carom_world *w, const step_context *ctx, const look_ahead *la,
                                     const look_ahead *lb, int with_turn)
{
    double speculative = w->def.speculative_distance;
    double spec = speculative;
    vec3 dv = v3_sub(la->velocity, lb->velocity);
    double l2 = v3_len2(dv) * (ctx->dt * ctx->dt);
    double turn = with_turn ? la->turn + lb->turn : 0.0;
    /* (the travel plus the turn stays under 0.9 of it) */
    if (turn <= 0.1 * spec && l2 < 0.64 * (spec * spec)) return spec;
    double closing = v3_len(dv) * ctx->dt + turn;
    if (closing > spec) spec = dmin(closing, speculative + 4.0 * WORLD_AABB_MARGIN);
    return spec;
}

/* The turns count against a static or kinematic body only. Its surface
 * near a contact is a face whose plane the turning body's anchored point
 * really crosses; between two dynamic bodies both anchors turn about the
 * step's fixed normal, and that linear guess closes gaps that never close
 * (seventy boxes spinning at 10 rad/s, 17 cm apart corner to corner, met
 * speculative contacts that braked them 1.65x faster than Coulomb's law).
 * There the sweep of toi.c stays the answer to fast turns. */
COLLIDE_INLINE double pair_look_ahead(const carom_world *w, const step_context *ctx, int a, int b)
{
    const body_store *s = &w->bodies;
    int with_turn = s->type[a] != CAROM_BODY_DYNAMIC || s->type[b] != CAROM_BODY_DYNAMIC;
    return look_ahead_of(w, ctx, &w->scratch.ahead[a], &w->scratch.ahead[b], with_turn);
}

/* (collision.h) */
double world_look_ahead_at_rest(const carom_world *w, const step_context *ctx, int slot)
{
    const look_ahead rest = {{0.0, 0.0, 0.0}, 0.0};
    return look_ahead_of(w, ctx, &w->scratch.ahead[slot], &rest, 1);
}

/* The narrowphase of a plain (not composite) pair whose fat bounds overlap:
 * its manifold refreshed, kept, or known empty; returns 1 when it has
 * points. a, b: the bodies' slots, awake_a, awake_b: body_awake of each.
 * Reads and writes contact i alone (and reads the bodies), so pairs run in
 * any order and at once, except that a pair without a data slot that finds
 * points takes one from the pool: only when may_add; else (run in parallel)
 * it returns -1 with the contact as it was, for the ordered pass to redo. */
COLLIDE_INLINE int narrow_contact(carom_world *w, const step_context *ctx, int i, int a, int b, int awake_a, int awake_b,
                                  double reuse, int may_add)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    step_scratch *sc = &w->scratch;
    contact *c = &cs->items[i];
    contact_data *d = CONTACT_DATA(cs, i);
    double spec = pair_look_ahead(w, ctx, a, b);
    /* bounds farther apart than the look-ahead: no point can be within it
     * (the gap between boxes bounds the distance), so skip the narrowphase */
    const aabb *ba = awake_a ? &sc->tight_box[a] : &s->fat_box[a], *bb = awake_b ? &sc->tight_box[b] : &s->fat_box[b];
    if (!aabb_overlap(aabb_fatten(*ba, spec), *bb)) {
        if (c->flags & CONTACT_TOUCHING) d->m.count = 0; /* else the manifold is already empty */
        return 0;
    }
    xform xa_own, xb_own;
    const xform *xa = awake_a ? &sc->pose[a] : (xa_own = body_xform(s, a), &xa_own);
    const xform *xb = awake_b ? &sc->pose[b] : (xb_own = body_xform(s, b), &xb_own);
    xform now = relative_pose(xa, xb);
    if (reuse_manifold(c, d, xa, &now, reuse, &s->shapes[a], &s->shapes[b]))
        return 1; /* kept: ids, impulses and feature cache stay as they were */
    if (still_apart(c, &now, spec)) return 0;
    const manifold *m = &d->m;
    manifold found;
    if (!c->slot) {
        /* most pairs near contact: no data yet, and most find none */
        manifold none;
        none.count = 0;
        collide_cache kept;
        if (!may_add) kept = c->cache; /* (may_add is a constant where this is inlined) */
        collide(&s->shapes[a], *xa, &s->shapes[b], *xb, spec, &c->cache, &found);
        m = &found;
        if (found.count > 0) {
            if (!may_add) { c->cache = kept; return -1; }
            if (!contact_data_alloc(cs, i)) return 0; /* out of memory: no manifold, tried again next step */
            c = &cs->items[i];
            d = CONTACT_DATA(cs, i);
            material_mix_contact(w, i);
            d->m = found;
            m = &d->m;
            contact_match_points(d, &none, d->state, *xa);
        }
    } else if (d->m.count == 0) {
        /* nothing to carry over, nothing to copy */
        manifold none;
        none.count = 0;
        collide(&s->shapes[a], *xa, &s->shapes[b], *xb, spec, &c->cache, &d->m);
        if (d->m.count > 0) contact_match_points(d, &none, d->state, *xa);
    } else {
        manifold old_m = d->m;
        contact_point_state old_state[MANIFOLD_MAX_POINTS];
        memcpy(old_state, d->state, sizeof old_state[0] * (size_t)old_m.count);
        collide(&s->shapes[a], *xa, &s->shapes[b], *xb, spec, &c->cache, &d->m);
        if (d->m.count > 0) contact_match_points(d, &old_m, old_state, *xa);
    }
    remember_pose(c, d, m, &s->shapes[a], *xa, &s->shapes[b], *xb, spec, &now);
    return m->count > 0;
}

/* Refreshes the manifold(s) of contact i (a pair's own contact, sub 0, with
 * at least one body awake), raises its begin/end events, lists it as
 * touching and wakes a sleeping body it touches (counted in *woken). A pair
 * whose bounds no longer overlap is removed when may_remove (returns 0:
 * index i now holds another contact), else only emptied. a, b: the
 * bodies' slots, awake_a, awake_b: body_awake of each (the caller's test). */
/* Whether composite contact i can name its pair in a begin event (it has
 * points) or an end event (it had them last step). */
static int speaks_for_pair(const contact_set *cs, int i, int touching)
{
    if (touching) return CONTACT_DATA(cs, i)->m.count > 0;
    return (cs->items[i].flags & CONTACT_WAS_TOUCHING) != 0;
}

/* A composite pair's contact (sub 0) without a manifold this step or last:
 * its normal and material are read again only after a manifold is written
 * into it, so they are made what a snapshot restores (no normal and the
 * mixed material, or no record at all), and a restored world steps on as
 * the original. (A stale normal here was written into the next snapshot
 * once another child pair touched, ANY_TOUCHING, and a restored world's
 * snapshots then differed from the original's.) */
static void forget_empty_record(carom_world *w, int i)
{
    contact_set *cs = &w->contacts;
    if (!cs->items[i].slot) return;
    contact_data *d = CONTACT_DATA(cs, i);
    d->m.normal = v3(0, 0, 0);
    if (d->tangent1.x == 0 && d->tangent1.y == 0 && d->tangent1.z == 0) contact_data_release(cs, i);
    else material_mix_contact(w, i);
}

COLLIDE_INLINE int update_contact(carom_world *w, const step_context *ctx, int i, int a, int b, int awake_a, int awake_b,
                                  double reuse, int may_remove, int *woken)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    step_scratch *sc = &w->scratch;
    contact *c = &cs->items[i];
    contact_data *d = CONTACT_DATA(cs, i);
    int composite = shape_is_composite(&s->shapes[a]) || shape_is_composite(&s->shapes[b]);
    int bounds_overlap = aabb_overlap(s->fat_box[a], s->fat_box[b]);
    if (!bounds_overlap && may_remove) {
        if (c->flags & (CONTACT_TOUCHING | CONTACT_ANY_TOUCHING)) events_touch(w, i, CAROM_EVENT_END);
        contact_remove(cs, i);
        return 0;
    }
    int touching = 0; /* known without reading the manifold where possible */
    if (composite) {
        double spec = pair_look_ahead(w, ctx, a, b);
        /* bounds farther apart than the look-ahead: no point can be within it */
        aabb ba = awake_a ? sc->tight_box[a] : s->fat_box[a], bb = awake_b ? sc->tight_box[b] : s->fat_box[b];
        xform xa = awake_a ? sc->pose[a] : body_xform(s, a), xb = awake_b ? sc->pose[b] : body_xform(s, b);
        int near = bounds_overlap && aabb_overlap(aabb_fatten(ba, spec), bb);
        touching = collide_composite_pair(w, i, xa, xb, spec, near);
        c = &cs->items[i]; /* extra contacts may have moved the arrays */
        d = CONTACT_DATA(cs, i);
        int was = (c->flags & CONTACT_ANY_TOUCHING) != 0;
        c->flags = (c->flags & ~(uint32_t)CONTACT_ANY_TOUCHING) | (touching ? CONTACT_ANY_TOUCHING : 0);
        if (touching && (!awake_a || !awake_b)) {
            if (!awake_a && s->type[a] != CAROM_BODY_STATIC) { wake_for_step(w, a); (*woken)++; }
            if (!awake_b && s->type[b] != CAROM_BODY_STATIC) { wake_for_step(w, b); (*woken)++; }
        }
        if (touching != was) {
            /* the event speaks of the pair: a manifold with points (begin),
             * or one that had them last step (end: its last normal) */
            int ei = i;
            for (uint32_t k = 1; !speaks_for_pair(cs, ei, touching) && k < c->sub_limit; k++) {
                int e = contact_find_sub(cs, c->id_a, c->id_b, k);
                if (e >= 0 && speaks_for_pair(cs, e, touching)) ei = e;
            }
            events_touch(w, ei, touching ? CAROM_EVENT_BEGIN : CAROM_EVENT_END);
        }
        if (d->m.count > 0) list_touching(sc, s, i, a, b);
        else if (!(c->flags & CONTACT_WAS_TOUCHING)) forget_empty_record(w, i);
        return 1;
    }
    if (bounds_overlap) {
        touching = narrow_contact(w, ctx, i, a, b, awake_a, awake_b, reuse, 1);
    } else if (c->flags & CONTACT_TOUCHING) { /* else the manifold is already empty */
        d->m.count = 0;
    }
    int was = (c->flags & CONTACT_TOUCHING) != 0;
    c->flags = (c->flags & ~(uint32_t)(CONTACT_TOUCHING | CONTACT_WAS_TOUCHING)) |
               (touching ? CONTACT_TOUCHING : 0) | (was ? CONTACT_WAS_TOUCHING : 0) | CONTACT_SIM;
    if (touching && (!awake_a || !awake_b)) {
        /* an awake body touching a sleeping one wakes it for this very step */
        if (!awake_a && s->type[a] != CAROM_BODY_STATIC) { wake_for_step(w, a); (*woken)++; }
        if (!awake_b && s->type[b] != CAROM_BODY_STATIC) { wake_for_step(w, b); (*woken)++; }
    }
    if (touching && !was) events_touch(w, i, CAROM_EVENT_BEGIN);
    else if (!touching && was) events_touch(w, i, CAROM_EVENT_END);
    if (touching) list_touching(sc, s, i, a, b);
    else if (c->slot && contact_data_idle(cs, i)) contact_data_release(cs, i); /* nothing left to keep */
    return 1;
}

/* Contacts per range handed to the task hooks. */
#define CONTACT_MIN_RANGE 64

typedef struct precompute_job {
    carom_world *w;
    const step_context *ctx;
    double reuse;
} precompute_job;

/* The narrowphase of every plain pair whose outcome the ordered pass below
 * cannot change: both bodies awake or static (waking only turns sleeping
 * bodies awake, and the pass removes no pair that passes these tests), its
 * filter bits allowing it and its bounds overlapping. The pass then takes
 * each one's result from its flags instead of computing it. */
static void precompute_range(int begin, int end, int worker, void *p)
{
    const precompute_job *j = p;
    carom_world *w = j->w;
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    (void)worker;
    for (int i = begin; i < end; i++) {
        contact *c = &cs->items[i];
        if (c->sub) continue;
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        int awake_a = body_awake(s, a), awake_b = body_awake(s, b);
        if (!(awake_a || awake_b) || !(awake_a || s->type[a] == CAROM_BODY_STATIC) ||
            !(awake_b || s->type[b] == CAROM_BODY_STATIC))
            continue;
        if (shape_is_composite(&s->shapes[a]) || shape_is_composite(&s->shapes[b])) continue;
        if (!aabb_overlap(s->fat_box[a], s->fat_box[b]) || !filter_bits_allow(s, a, b)) continue;
        int touching = narrow_contact(w, j->ctx, i, a, b, awake_a, awake_b, j->reuse, 0);
        if (touching < 0) continue; /* needs a data slot: the ordered pass computes it */
        c->flags |= CONTACT_PRECOMPUTED | (touching ? CONTACT_PRECOMPUTED_TOUCHING : 0u) |
                    (pair_is_mixed(s, a, b) ? CONTACT_PRECOMPUTED_MIXED : 0u);
    }
}

/* The ordered pass's part of a precomputed contact i (update_contact's
 * plain-pair path with its outcome known): its flags, its begin/end event,
 * its place in the touching list. Both bodies are awake or static, so
 * nothing wakes, and the contact reads no body: at 50,000 boxes the ordered
 * pass's reads of the bodies' ids, types, flags, shapes and bounds, scattered
 * over the world, were most of the stage's serial time at 2 workers. */
static void finish_precomputed(carom_world *w, int i)
{
    contact_set *cs = &w->contacts;
    contact *c = &cs->items[i];
    uint32_t f = c->flags;
    int touching = (f & CONTACT_PRECOMPUTED_TOUCHING) != 0, was = (f & CONTACT_TOUCHING) != 0;
    c->flags = (f & ~(uint32_t)(CONTACT_PRECOMPUTED | CONTACT_PRECOMPUTED_TOUCHING | CONTACT_PRECOMPUTED_MIXED |
                                CONTACT_TOUCHING | CONTACT_WAS_TOUCHING)) |
               (touching ? CONTACT_TOUCHING : 0) | (was ? CONTACT_WAS_TOUCHING : 0) | CONTACT_SIM;
    if (touching && !was) events_touch(w, i, CAROM_EVENT_BEGIN);
    else if (!touching && was) events_touch(w, i, CAROM_EVENT_END);
    if (touching) list_touching_as(&w->scratch, i, (f & CONTACT_PRECOMPUTED_MIXED) != 0);
    else if (c->slot && contact_data_idle(cs, i)) contact_data_release(cs, i); /* nothing left to keep */
}

int world_collide(carom_world *w, const step_context *ctx)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    step_scratch *sc = &w->scratch;
    /* within the look-ahead, a feature not yet in a manifold cannot reach
     * contact while the manifold is kept */
    double reuse = dmin(w->def.contact_reuse_distance, w->def.speculative_distance);
    sc->touching_count = 0;
    sc->mixed_count = 0;
    sc->asleep_pair_count = 0;
    /* at most every contact is touching (or asleep): reserve once, so nothing below can fail */
    if (!array_reserve_near((void **)&sc->touching, &sc->touching_capacity, cs->count, sizeof *sc->touching) ||
        !array_reserve_near((void **)&sc->mixed, &sc->mixed_capacity, cs->count, sizeof *sc->mixed))
        return 0;
    if (!array_reserve_near((void **)&sc->asleep_pairs, &sc->asleep_pair_capacity, cs->count, sizeof *sc->asleep_pairs))
        return 0;
    /* on one worker the pass below does the same work in place */
    if (tasks_workers(&w->def) > 1) {
        precompute_job job = {w, ctx, reuse};
        tasks_run(&w->def, cs->count, CONTACT_MIN_RANGE, precompute_range, &job);
    }
    /* ascending, and a removal re-examines index i (the last contact, not yet
     * seen, moves there), so the indices already listed stay valid */
    int woken = 0;
    /* contacts begin only where the bits allow them (add_pair): they can
     * forbid one only after set_filter (or in a restored world) */
    int check_filters = !w->filters_settled;
    /* whether any extra manifold can be listed at the end: one is seen below
     * (those a composite pair adds in this pass are appended, so seen too),
     * or a composite pair is woken after it */
    int subs = 0;
    for (int i = 0; i < cs->count;) {
        contact *c = &cs->items[i];
        if (c->flags & CONTACT_PRECOMPUTED) { /* (a pair's own contact, filters passed: precompute_range) */
            finish_precomputed(w, i++);
            continue;
        }
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        if (c->sub) {
            subs = 1;
            /* an extra manifold of a mesh pair: the pair's own contact (sub 0)
             * computes it; it goes when the pair does */
            if (!aabb_overlap(s->fat_box[a], s->fat_box[b]) || (check_filters && !filter_bits_allow(s, a, b)))
                contact_remove(cs, i);
            else i++;
            continue;
        }
        c->flags &= ~(uint32_t)CONTACT_SIM;
        if (check_filters && !filter_bits_allow(s, a, b)) { /* the bits changed since the pair was made */
            if (c->flags & (CONTACT_TOUCHING | CONTACT_ANY_TOUCHING)) events_touch(w, i, CAROM_EVENT_END);
            contact_remove(cs, i);
            continue;
        }
        int awake_a = body_awake(s, a), awake_b = body_awake(s, b);
        if (!awake_a && !awake_b) {
            /* a sleeping pair keeps its manifold, unless a body woken later in
             * this pass reaches it (below) */
            if (sc->asleep_pair_count < sc->asleep_pair_capacity) sc->asleep_pairs[sc->asleep_pair_count++] = i;
            i++;
            continue;
        }
        if (update_contact(w, ctx, i, a, b, awake_a, awake_b, reuse, 1, &woken)) i++;
    }
    w->filters_settled = 1;
    /* Waking spreads through touching pairs whatever their order in the
     * cache: a body woken above takes part in all its pairs this step, so it
     * never passes through a sleeping neighbour. Repeats until no pair wakes
     * another body (each round wakes at least one, so it ends). Nothing is
     * removed here (a mesh pair may add extra contacts at the end), so the
     * indices listed stay valid. */
    while (woken > 0) {
        woken = 0;
        for (int k = 0; k < sc->asleep_pair_count;) {
            int i = sc->asleep_pairs[k];
            contact *c = &cs->items[i];
            int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
            int awake_a = body_awake(s, a), awake_b = body_awake(s, b);
            if (!awake_a && !awake_b) { k++; continue; }
            sc->asleep_pairs[k] = sc->asleep_pairs[--sc->asleep_pair_count];
            subs |= shape_is_composite(&s->shapes[a]) || shape_is_composite(&s->shapes[b]);
            if (!array_reserve((void **)&sc->touching, &sc->touching_capacity, sc->touching_count + 1,
                               sizeof *sc->touching) ||
                !array_reserve((void **)&sc->mixed, &sc->mixed_capacity, sc->touching_count + 1, sizeof *sc->mixed))
                return 0;
            update_contact(w, ctx, i, a, b, awake_a, awake_b, reuse, 0, &woken);
        }
    }
    /* the extra manifolds of the mesh pairs computed above (a pass over
     * every contact: 22 % of this stage's own time at 50,000 boxes, where
     * there are none) */
    if (!subs) return 1;
    if (!array_reserve((void **)&sc->touching, &sc->touching_capacity, cs->count, sizeof *sc->touching) ||
        !array_reserve((void **)&sc->mixed, &sc->mixed_capacity, cs->count, sizeof *sc->mixed))
        return 0;
    for (int i = 0; i < cs->count; i++) {
        const contact *c = &cs->items[i];
        if (!c->sub || !(c->flags & CONTACT_TOUCHING)) continue;
        int primary = contact_find(cs, c->id_a, c->id_b);
        if (primary >= 0 && (cs->items[primary].flags & CONTACT_SIM))
            list_touching(sc, s, i, s->ids[c->id_a].slot, s->ids[c->id_b].slot);
    }
    return 1;
}

/* ---- falling asleep: a cache the bodies' own state reproduces ----------------------- */

/* A resting state is known to the solver's tolerance (micrometres), not to
 * the last bit: a sleeping island's lengths (centres, orientation
 * components, unit vectors, points in A's frame, separations) are rounded to
 * multiples of 2^-30 (9.3e-10 m; a coordinate past 2^22 m keeps its own
 * ulp), its impulses to 28 significant bits (relative 3.7e-9). Rounded
 * values share their low bits, so a snapshot codes them in fewer bytes
 * (docs/snapshot.md); the step reads them as it reads any value. */
static double settle_length(double x) { return ldexp(nearbyint(ldexp(x, 30)), -30); }
static vec3 settle_v3(vec3 v) { return v3(settle_length(v.x), settle_length(v.y), settle_length(v.z)); }
static double settle_impulse(double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    u = (u + ((uint64_t)1 << 23)) & ~(((uint64_t)1 << 24) - 1); /* to nearest (a carry into the exponent is right) */
    memcpy(&x, &u, sizeof x);
    return x;
}

void world_settle_body(carom_world *w, int slot)
{
    body_store *s = &w->bodies;
    s->center[slot] = settle_v3(s->center[slot]);
    quat q = s->rotation[slot];
    /* (|q| stays within 2^-29 of 1: the step normalises it when it turns) */
    s->rotation[slot] = (quat){settle_length(q.w), settle_length(q.x), settle_length(q.y), settle_length(q.z)};
    body_update_inertia(s, slot);
    /* asleep: past the island's threshold (what body_set_awake(0) sets) */
    s->sleep_time[slot] = w->def.sleep_time;
    /* the pose its pairs are settled at (world_settle_contacts) */
    s->collided[slot] = body_xform(s, slot);
    /* bounds fattened about where it rests, as a body at rest's are
     * (world_body_fat_aabb): the last move's bounds were about an older pose */
    aabb fat = world_body_fat_aabb(w, slot, WORLD_AABB_MARGIN);
    if (memcmp(&fat, &s->fat_box[slot], sizeof fat) != 0) {
        s->fat_box[slot] = fat;
        bp_move_proxy(w->bp, s->proxy[slot], fat);
    }
}

/* Contact i, both of whose bodies are now asleep or static. What the cache
 * held from the poses of earlier narrowphase tests goes: the reuse pose (the
 * first test after waking runs the narrowphase afresh), the apart bound, the
 * last normal of a pair that no longer touches, the kept friction basis (the
 * tangent impulses re-expressed in the basis the solver builds from the
 * normal, contact_rest_basis: the same impulse). The manifold's points stay,
 * held in A's frame at its collided pose with the world points made from
 * them, so both follow from the bodies and the points in A's frame. */
static void settle_contact(carom_world *w, int i)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    contact *c = &cs->items[i];
    c->flags &= ~(uint32_t)(CONTACT_REUSABLE | CONTACT_APART);
    const contact_data *d0 = CONTACT_DATA(cs, i);
    int normal_read = d0->m.count > 0 || (c->flags & (CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_ANY_TOUCHING));
    if (!normal_read) {
        c->cache.has_normal = 0;
        c->cache.normal = v3(0, 0, 0);
    }
    if (!c->slot) {
        if (c->cache.has_normal) c->cache.normal = settle_v3(c->cache.normal);
        return;
    }
    contact_data *d = CONTACT_DATA(cs, i);
    if (normal_read) d->m.normal = settle_v3(d->m.normal);
    if (c->cache.has_normal) c->cache.normal = normal_read ? d->m.normal : settle_v3(c->cache.normal);
    xform xa = s->collided[s->ids[c->id_a].slot];
    for (int k = 0; k < d->m.count; k++) {
        manifold_point *p = &d->m.points[k];
        contact_point_state *st = &d->state[k];
        st->local_a = settle_v3(xf_inv_point(xa, p->point));
        p->point = xf_point(xa, st->local_a);
        p->separation = st->separation = settle_length(p->separation);
        st->normal_impulse = settle_impulse(st->normal_impulse);
    }
    if (d->m.count == 0) {
        d->tangent1 = v3(0, 0, 0);
    } else if (c->cache.has_normal && (d->tangent1.x != 0 || d->tangent1.y != 0 || d->tangent1.z != 0)) {
        vec3 n = d->m.normal, t1 = d->tangent1, t2 = v3_cross(n, t1);
        vec3 u1 = contact_rest_basis(n), u2 = v3_cross(n, u1);
        for (int k = 0; k < d->m.count; k++) {
            contact_point_state *st = &d->state[k];
            vec3 j = v3_add(v3_scale(t1, st->tangent_impulse[0]), v3_scale(t2, st->tangent_impulse[1]));
            st->tangent_impulse[0] = v3_dot(j, u1);
            st->tangent_impulse[1] = v3_dot(j, u2);
        }
        d->tangent1 = u1;
    }
    for (int k = 0; k < d->m.count; k++) {
        d->state[k].tangent_impulse[0] = settle_impulse(d->state[k].tangent_impulse[0]);
        d->state[k].tangent_impulse[1] = settle_impulse(d->state[k].tangent_impulse[1]);
    }
    if (!(c->flags & (CONTACT_TOUCHING | CONTACT_ANY_TOUCHING)) && contact_data_idle(cs, i)) contact_data_release(cs, i);
}

void world_settle_contacts(carom_world *w)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    for (int i = 0; i < cs->count; i++) {
        const contact *c = &cs->items[i];
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        if (body_awake(s, a) || body_awake(s, b)) continue;
        /* only pairs this step tested (an extra manifold: its pair's contact says) */
        int primary = c->sub ? contact_find(cs, c->id_a, c->id_b) : i;
        if (primary < 0 || !(cs->items[primary].flags & CONTACT_SIM)) continue;
        settle_contact(w, i);
    }
}
