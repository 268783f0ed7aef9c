/* fuzz_common.h - invariants the harnesses check after every step. */
#ifndef CAROM_FUZZ_COMMON_H
#define CAROM_FUZZ_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "carom/carom.h"

#define FUZZ_CHECK(cond, ...)                                                                        \
    do {                                                                                             \
        if (!(cond)) {                                                                               \
            fprintf(stderr, "invariant broken: %s (%s:%d): ", #cond, __FILE__, __LINE__);            \
            fprintf(stderr, __VA_ARGS__);                                                            \
            fprintf(stderr, "\n");                                                                   \
            abort();                                                                                 \
        }                                                                                            \
    } while (0)

static inline int fuzz_finite3(carom_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

/* The body ids of a world (query over everything: planes' bounds are huge but finite). */
static inline int fuzz_bodies(const carom_world *w, carom_body_id *ids, int cap)
{
    carom_vec3 lo = {-1e300, -1e300, -1e300}, hi = {1e300, 1e300, 1e300};
    return carom_world_query_aabb(w, lo, hi, ids, cap);
}

/* No NaN or infinity in state, events or probes. */
static inline void fuzz_assert_world_finite(const carom_world *w)
{
    carom_body_id ids[512];
    int n = fuzz_bodies(w, ids, 512);
    FUZZ_CHECK(n == carom_world_body_count(w), "query finds %d of %d bodies", n, carom_world_body_count(w));
    for (int i = 0; i < n && i < 512; i++) {
        carom_vec3 p, v, av;
        carom_quat q;
        double ke;
        FUZZ_CHECK(carom_body_get_position(w, ids[i], &p) == CAROM_OK && fuzz_finite3(p), "position");
        FUZZ_CHECK(carom_body_get_linear_velocity(w, ids[i], &v) == CAROM_OK && fuzz_finite3(v), "velocity");
        FUZZ_CHECK(carom_body_get_angular_velocity(w, ids[i], &av) == CAROM_OK && fuzz_finite3(av), "spin");
        FUZZ_CHECK(carom_body_get_orientation(w, ids[i], &q) == CAROM_OK && isfinite(q.w + q.x + q.y + q.z), "orientation");
        FUZZ_CHECK(carom_body_get_kinetic_energy(w, ids[i], &ke) == CAROM_OK && isfinite(ke), "kinetic energy");
    }
    const carom_contact_event *ev;
    int ne = carom_world_get_events(w, &ev);
    for (int i = 0; i < ne; i++) {
        FUZZ_CHECK(fuzz_finite3(ev[i].point) && fuzz_finite3(ev[i].normal), "event point or normal");
        FUZZ_CHECK(isfinite(ev[i].normal_impulse) && isfinite(ev[i].tangent_impulse), "event impulse");
        FUZZ_CHECK(isfinite(ev[i].approach_speed) && isfinite(ev[i].average_force), "event speed or force");
    }
    carom_world_stats st = carom_world_stats_init();
    FUZZ_CHECK(carom_world_get_stats(w, &st) == CAROM_OK, "stats");
    FUZZ_CHECK(st.non_finite == 0, "%d bodies went non-finite", st.non_finite);
    FUZZ_CHECK(isfinite(st.max_penetration), "max penetration");
    double k, pe;
    carom_vec3 lin, ang;
    FUZZ_CHECK(carom_world_get_energy(w, &k, &pe) == CAROM_OK && isfinite(k) && isfinite(pe), "energy");
    FUZZ_CHECK(carom_world_get_momentum(w, &lin, &ang) == CAROM_OK && fuzz_finite3(lin) && fuzz_finite3(ang), "momentum");
    FUZZ_CHECK(isfinite(carom_world_measure_max_penetration(w)), "measured penetration");
    carom_ray_hit hit;
    carom_vec3 o = {0.1, 0.2, 50}, d = {0, 0, -100};
    if (carom_world_ray_cast(w, o, d, &hit) == 1)
        FUZZ_CHECK(fuzz_finite3(hit.point) && fuzz_finite3(hit.normal) && isfinite(hit.fraction), "ray hit");
}

/* Rewrites a snapshot's size and checksum fields (docs/snapshot.md). */
static inline void fuzz_fix_snapshot_header(unsigned char *p, size_t n)
{
    for (int k = 0; k < 8; k++) p[16 + k] = (unsigned char)((uint64_t)n >> (8 * k));
    const unsigned char *q = p + 32;
    size_t m = n - 32, i = 0;
    uint64_t lane[4], h;
    for (int k = 0; k < 4; k++) lane[k] = 0x9e3779b97f4a7c15ULL ^ (uint64_t)m ^ ((uint64_t)k << 56);
    for (; i + 32 <= m; i += 32)
        for (int k = 0; k < 4; k++) {
            uint64_t v = 0;
            for (int b = 7; b >= 0; b--) v = (v << 8) | q[i + 8 * (size_t)k + (size_t)b];
            lane[k] = (lane[k] ^ v) * 0xff51afd7ed558ccdULL;
            lane[k] ^= lane[k] >> 29;
        }
    h = lane[0];
    for (int k = 1; k < 4; k++) {
        h = (h ^ lane[k]) * 0xff51afd7ed558ccdULL;
        h ^= h >> 29;
    }
    for (; i + 8 <= m; i += 8) {
        uint64_t v = 0;
        for (int k = 7; k >= 0; k--) v = (v << 8) | q[i + (size_t)k];
        h = (h ^ v) * 0xff51afd7ed558ccdULL;
        h ^= h >> 29;
    }
    for (; i < m; i++) {
        h = (h ^ q[i]) * 0xc4ceb9fe1a85ec53ULL;
        h ^= h >> 31;
    }
    for (int k = 0; k < 8; k++) p[24 + k] = (unsigned char)(h >> (8 * k));
}

#endif
