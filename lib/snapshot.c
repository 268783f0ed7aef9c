/* snapshot.c - a world's complete state as bytes, and a world built back
 * from them (docs/snapshot.md has the format). Everything the step reads
 * from one step to the next is written: settings, the id table with its
 * generations and free list, every body field that is not derived from the
 * others, shapes (hulls whole), the contact cache with its manifolds and
 * warm-start impulses, sleep timers, the broadphase's pending (moved) set.
 * Derived state (inverse masses and inertias, the broadphase trees, the pair
 * map) is rebuilt by the same code that built it, so a restored world
 * continues bit for bit.
 *
 * The reader trusts nothing: every count is checked against the bytes left
 * before anything is allocated, every index against its table, every number
 * against the ranges the API enforces; the first failure names what was
 * wrong and nothing is built. */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "ranges.h"
#include "narrowphase.h"
#include "mesh.h"
#include "heightfield.h"
#include "compound.h"
#include "material.h"
#include "snapshot.h"

#define SNAP_MAGIC "CAROMSNP"
#define SNAP_VERSION 8u
/* The oldest format the reader still takes: 7 differs only in how a
 * contact names its two bodies (docs/snapshot.md, "Format 7"). */
#define SNAP_VERSION_OLDEST 7u
#define SNAP_HEADER_SIZE 32u

/* ---- writer: little-endian whatever the host ----------------------------------- */

/* On a little-endian host the bytes are the value's own: one copy (the
 * portable byte loops below are the definition, and the big-endian path). */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define SNAP_HOST_LE 1
#else
#define SNAP_HOST_LE 0
#endif

/* The hot readers and writers, inlined into every record's loop (GCC and
 * clang otherwise keep the larger ones out of line: a call per value). */
#if defined(__GNUC__)
#define SNAP_INLINE static inline __attribute__((always_inline))
#else
#define SNAP_INLINE static inline
#endif

typedef struct writer {
    unsigned char *buf;
    size_t cap, pos;
    size_t *acct;           /* snapshot_field_bytes: bytes per field, else NULL */
} writer;

/* The bytes written since `since` go to field f (snapshot_field_bytes). */
static void acct(writer *o, int f, size_t since)
{
    if (o->acct) o->acct[f] += o->pos - since;
}

static void put_bytes(writer *o, const void *p, size_t n)
{
    if (o->pos + n <= o->cap) memcpy(o->buf + o->pos, p, n);
    o->pos += n;
}

static void put_u64(writer *o, uint64_t v)
{
    if (o->pos + 8 <= o->cap) {
        unsigned char *b = o->buf + o->pos;
        if (SNAP_HOST_LE) memcpy(b, &v, 8);
        else for (int i = 0; i < 8; i++) b[i] = (unsigned char)(v >> (8 * i));
    }
    o->pos += 8;
}

static void put_u32(writer *o, uint32_t v)
{
    if (o->pos + 4 <= o->cap) {
        unsigned char *b = o->buf + o->pos;
        if (SNAP_HOST_LE) memcpy(b, &v, 4);
        else for (int i = 0; i < 4; i++) b[i] = (unsigned char)(v >> (8 * i));
    }
    o->pos += 4;
}

static void put_u8(writer *o, unsigned v)
{
    if (o->pos < o->cap) o->buf[o->pos] = (unsigned char)v;
    o->pos++;
}

static void put_i32(writer *o, int v) { put_u32(o, (uint32_t)v); }
static void put_f64(writer *o, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    put_u64(o, v);
}
static void put_v3(writer *o, vec3 v) { put_f64(o, v.x); put_f64(o, v.y); put_f64(o, v.z); }
static void put_q(writer *o, quat q) { put_f64(o, q.w); put_f64(o, q.x); put_f64(o, q.y); put_f64(o, q.z); }
static void put_m3(writer *o, mat3 m) { put_v3(o, m.c0); put_v3(o, m.c1); put_v3(o, m.c2); }

/* ---- reader: bounds-checked, the first error sticks ---------------------------- */

typedef struct reader {
    const unsigned char *buf;
    size_t size, pos;
    char *msg;
    size_t msg_size;
    int failed;
    unsigned version;       /* the snapshot's format (SNAP_VERSION_OLDEST .. SNAP_VERSION) */
    int out_of_memory;      /* the failure was memory, not the data */
    carom_world *into;      /* a world whose memory the state is to be read into (restore_into's
                               spare), until read_world takes it; NULL: a new world */
    int reuse;              /* the world read into is such a one */
} reader;

/* The reader's pose checks: a quaternion more than 1e-6 from unit length, and
 * a vector inside the cube |x|, |y|, |z| <= limit (NaN fails it). */
static int not_unit(quat q) { return fabs(q_len(q) - 1.0) > 1e-6; }
static int within_cube(vec3 v, double limit) { return fabs(v.x) <= limit && fabs(v.y) <= limit && fabs(v.z) <= limit; }
/* A direction the state holds (manifold normal, cache normal, normal in A's
 * frame, friction basis): zero where unused, else unit as computed; the
 * narrowphase itself keeps any normal of length^2 >= 0.5, so the reader takes
 * lengths in [0.5, 2] (a fuzzed normal of length 4.8e232 made 2 bodies NaN) */
static int bad_direction(vec3 v)
{
    if (v.x == 0 && v.y == 0 && v.z == 0) return 0;
    double l = v3_len(v);
    return !(l >= 0.5 && l <= 2.0);
}

static int bad(reader *r, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#include <stdarg.h>
static int bad(reader *r, const char *fmt, ...)
{
    if (!r->failed && r->msg && r->msg_size) {
        va_list ap;
        va_start(ap, fmt);
        int n = snprintf(r->msg, r->msg_size, "snapshot: ");
        if (n >= 0 && (size_t)n < r->msg_size) vsnprintf(r->msg + n, r->msg_size - (size_t)n, fmt, ap);
        va_end(ap);
    }
    r->failed = 1;
    return 0;
}

static int no_memory(reader *r)
{
    r->out_of_memory = !r->failed;
    return bad(r, "out of memory");
}

static int need(reader *r, size_t n, const char *what)
{
    if (r->failed) return 0;
    if (n > r->size - r->pos) return bad(r, "truncated: %s needs %zu bytes at offset %zu, %zu left", what, n, r->pos,
                                         r->size - r->pos);
    return 1;
}

static uint64_t get_u64(reader *r, const char *what)
{
    if (!need(r, 8, what)) return 0;
    uint64_t v = 0;
    if (SNAP_HOST_LE) memcpy(&v, r->buf + r->pos, 8);
    else for (int i = 7; i >= 0; i--) v = (v << 8) | r->buf[r->pos + (size_t)i];
    r->pos += 8;
    return v;
}

static uint32_t get_u32(reader *r, const char *what)
{
    if (!need(r, 4, what)) return 0;
    uint32_t v = 0;
    if (SNAP_HOST_LE) memcpy(&v, r->buf + r->pos, 4);
    else for (int i = 3; i >= 0; i--) v = (v << 8) | r->buf[r->pos + (size_t)i];
    r->pos += 4;
    return v;
}

static unsigned get_u8(reader *r, const char *what)
{
    if (!need(r, 1, what)) return 0;
    return r->buf[r->pos++];
}

static int get_i32(reader *r, const char *what) { return (int)get_u32(r, what); }

/* A finite double (the state never holds anything else). */
static double get_f64(reader *r, const char *what)
{
    uint64_t v = get_u64(r, what);
    double d;
    memcpy(&d, &v, 8);
    if (!r->failed && !isfinite(d)) { bad(r, "%s is not finite", what); return 0; }
    return d;
}

static vec3 get_v3(reader *r, const char *what)
{
    vec3 v;
    v.x = get_f64(r, what);
    v.y = get_f64(r, what);
    v.z = get_f64(r, what);
    return v;
}

static quat get_q(reader *r, const char *what)
{
    quat q;
    q.w = get_f64(r, what);
    q.x = get_f64(r, what);
    q.y = get_f64(r, what);
    q.z = get_f64(r, what);
    return q;
}

static mat3 get_m3(reader *r, const char *what)
{
    mat3 m;
    m.c0 = get_v3(r, what);
    m.c1 = get_v3(r, what);
    m.c2 = get_v3(r, what);
    return m;
}

/* A count whose records take at least `record` bytes each must fit in what is left. */
static int get_count(reader *r, size_t record, int max, const char *what)
{
    uint32_t n = get_u32(r, what);
    if (r->failed) return 0;
    if (n > (uint32_t)max) return bad(r, "%s %u is above %d", what, n, max), 0;
    if ((size_t)n * record > r->size - r->pos) return bad(r, "truncated: %u %s need more than the %zu bytes left", n, what,
                                                           r->size - r->pos), 0;
    return (int)n;
}

/* ---- compact codes: varints, and doubles sent against a prediction -------------- */

static void put_varint_slow(writer *o, uint64_t v)
{
    while (v >= 0x80) { put_u8(o, (unsigned)(v & 0x7f) | 0x80u); v >>= 7; }
    put_u8(o, (unsigned)v);
}

/* (inlined: one or two bytes, with room, stored directly) */
SNAP_INLINE void put_varint(writer *o, uint64_t v)
{
    if (v < (1u << 14) && o->pos + 2 <= o->cap) {
        if (v < 0x80) {
            o->buf[o->pos++] = (unsigned char)v;
        } else {
            o->buf[o->pos] = (unsigned char)((v & 0x7f) | 0x80);
            o->buf[o->pos + 1] = (unsigned char)(v >> 7);
            o->pos += 2;
        }
        return;
    }
    put_varint_slow(o, v);
}

static uint64_t zigzag(int64_t v) { return ((uint64_t)v << 1) ^ (uint64_t)(v >> 63); }
static int64_t unzigzag(uint64_t u) { return (int64_t)(u >> 1) ^ -(int64_t)(u & 1); }

static uint64_t get_varint_slow(reader *r, const char *what)
{
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
        unsigned b = get_u8(r, what);
        if (r->failed) return 0;
        if (shift == 63 && b > 1) break;
        v |= (uint64_t)(b & 0x7f) << shift;
        if (!(b & 0x80)) {
            /* one encoding per value, so a restored world snapshots back to the same bytes */
            if (b == 0 && shift > 0) { bad(r, "%s: varint with a needless byte", what); return 0; }
            return v;
        }
    }
    bad(r, "%s: varint longer than 64 bits", what);
    return 0;
}

/* A varint that must fit an int in [lo, hi]. */
static int get_small_slow(reader *r, int64_t lo, int64_t hi, int is_signed, const char *what)
{
    uint64_t u = get_varint_slow(r, what);
    if (r->failed) return 0;
    int64_t v = is_signed ? unzigzag(u) : (u > (uint64_t)INT64_MAX ? -1 : (int64_t)u);
    if (v < lo || v > hi || (!is_signed && u > (uint64_t)INT64_MAX)) {
        bad(r, "%s %lld is outside [%lld, %lld]", what, (long long)v, (long long)lo, (long long)hi);
        return 0;
    }
    return (int)v;
}

/* A varint that must fit an int in [lo, hi]: one of up to 8 bytes in range
 * is taken here from one 8-byte load (inlined at every record's fields);
 * anything else is read, and refused, by the checked way above from the
 * same position. */
SNAP_INLINE int get_small(reader *r, int64_t lo, int64_t hi, int is_signed, const char *what)
{
    if (!r->failed && r->size - r->pos >= 10) {
        const unsigned char *p = r->buf + r->pos;
        uint64_t u;
        size_t len;
        if (p[0] < 0x80) {
            u = p[0], len = 1;
        } else if (p[1] < 0x80 && p[1] != 0) {
            u = (uint64_t)(p[0] & 0x7f) | (uint64_t)p[1] << 7, len = 2;
        } else {
#if defined(__GNUC__)
            /* up to 8 bytes from one load: the first byte without the
             * continuation bit ends it (and must not be 0: a needless byte) */
            uint64_t word = 0;
            if (SNAP_HOST_LE) memcpy(&word, p, 8);
            else for (int k = 7; k >= 0; k--) word = (word << 8) | p[k];
            uint64_t stop = ~word & 0x8080808080808080ULL;
            unsigned bit = stop ? (unsigned)__builtin_ctzll(stop) : 0; /* (the last byte's bit 7) */
            if (!stop || !((word >> (bit - 7)) & 0x7f)) return get_small_slow(r, lo, hi, is_signed, what);
            word &= ((stop & (0 - stop)) << 1) - 1; /* (its bytes: up to the stop bit; all 64 when it is bit 63) */
            u = (word & 0x7f) | (word >> 1 & 0x7fULL << 7) | (word >> 2 & 0x7fULL << 14) | (word >> 3 & 0x7fULL << 21) |
                (word >> 4 & 0x7fULL << 28) | (word >> 5 & 0x7fULL << 35) | (word >> 6 & 0x7fULL << 42) |
                (word >> 7 & 0x7fULL << 49);
            len = bit / 8 + 1;
#else
            return get_small_slow(r, lo, hi, is_signed, what);
#endif
        }
        int64_t v = is_signed ? unzigzag(u) : (int64_t)u;
        if (v >= lo && v <= hi) {
            r->pos += len;
            return (int)v;
        }
    }
    return get_small_slow(r, lo, hi, is_signed, what);
}

static uint64_t f64_bits(double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    return v;
}

/* Doubles sent as their bits XOR a prediction both sides compute from what is
 * already written (exact predictions are common: derived fields, poses that
 * did not change). Per value a 4-bit tag, two to a byte, before the group's
 * payloads: 0 equal to the prediction; 1..8 the XOR's low t bytes (its high
 * bytes are zero); 9..15 its high 16 - t bytes (its low t - 8 bytes are zero). */
#define CODED_MAX 8

/* The one tag the writer picks for an XOR (the reader refuses any other):
 * 0 for 0, else with lead / trail its leading / trailing zero bytes,
 * trail > lead ? 8 + trail (keep the high 8 - trail bytes) : 8 - lead (keep
 * the low 8 - lead bytes). Looked up by (lead, trail), both counted with a
 * bit set at the far end (0 alone gives (7, 7), which no other value does):
 * no branch, one table load (coded_tag_reference is the definition). */
static const unsigned char coded_tag_of_key[64] = {
    8, 9, 10, 11, 12, 13, 14, 15, 7, 7, 10, 11, 12, 13, 14, 15, 6, 6, 6, 11, 12, 13, 14, 15, 5, 5, 5, 5, 12, 13, 14, 15,
    4, 4, 4, 4, 4, 13, 14, 15, 3, 3, 3, 3, 3, 3, 14, 15, 2, 2, 2, 2, 2, 2, 2, 15, 1, 1, 1, 1, 1, 1, 1, 0};

static int coded_tag_reference(uint64_t x)
{
    if (x == 0) return 0;
    int lead = 0, trail = 0;
    while (!((x >> (56 - 8 * lead)) & 0xff)) lead++;
    while (!((x >> (8 * trail)) & 0xff)) trail++;
    /* (trail > lead implies trail > 0) */
    return trail > lead ? 8 + trail : 8 - lead;
}

SNAP_INLINE int coded_tag_by_key(uint64_t x)
{
#if defined(__GNUC__)
    unsigned lead = (unsigned)__builtin_clzll(x | 1) >> 3, trail = (unsigned)__builtin_ctzll(x | (uint64_t)1 << 63) >> 3;
    return coded_tag_of_key[lead * 8 + trail];
#else
    return coded_tag_reference(x);
#endif
}

/* The tag by which of the XOR's bytes are nonzero (bit k: byte k): where
 * SSE2 finds the zero bytes of two values at once (one compare, one mask). */
static const unsigned char coded_tag_of_bytes[256] = {
    0, 1, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 12, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5, 5,
    13, 6, 6, 6, 6, 6, 6, 6, 11, 6, 6, 6, 6, 6, 6, 6, 12, 6, 6, 6, 6, 6, 6, 6, 11, 6, 6, 6, 6, 6, 6, 6,
    14, 7, 7, 7, 10, 7, 7, 7, 11, 7, 7, 7, 10, 7, 7, 7, 12, 7, 7, 7, 10, 7, 7, 7, 11, 7, 7, 7, 10, 7, 7, 7,
    13, 7, 7, 7, 10, 7, 7, 7, 11, 7, 7, 7, 10, 7, 7, 7, 12, 7, 7, 7, 10, 7, 7, 7, 11, 7, 7, 7, 10, 7, 7, 7,
    15, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8, 12, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8,
    13, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8, 12, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8,
    14, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8, 12, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8,
    13, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8, 12, 8, 9, 8, 10, 8, 9, 8, 11, 8, 9, 8, 10, 8, 9, 8};

#if defined(__SSE2__) && SNAP_HOST_LE
#include <emmintrin.h>
#define SNAP_SSE2 1
#else
#define SNAP_SSE2 0
#endif

/* The tags of two values (of one, with x1 0). */
SNAP_INLINE void coded_tag2(uint64_t x0, uint64_t x1, unsigned *t0, unsigned *t1)
{
#if SNAP_SSE2
    __m128i v = _mm_set_epi64x((long long)x1, (long long)x0);
    unsigned nonzero = ~(unsigned)_mm_movemask_epi8(_mm_cmpeq_epi8(v, _mm_setzero_si128()));
    *t0 = coded_tag_of_bytes[nonzero & 255];
    *t1 = coded_tag_of_bytes[(nonzero >> 8) & 255];
#else
    *t0 = (unsigned)coded_tag_by_key(x0);
    *t1 = (unsigned)coded_tag_by_key(x1);
#endif
}

SNAP_INLINE int coded_tag(uint64_t x)
{
    unsigned t0, t1;
    coded_tag2(x, 0, &t0, &t1);
    return (int)t0;
}

/* The tables against the definition: every pattern of zero and nonzero
 * bytes, each nonzero byte 0x01, 0x80 or 0xff, as one value and as either
 * of a pair (tests/test_snapshot.c). */
int snapshot_coded_tags_disagree(void)
{
    static const unsigned byte[3] = {0x01, 0x80, 0xff};
    int wrong = 0;
    for (unsigned pattern = 0; pattern < 256; pattern++)
        for (unsigned b = 0; b < 3; b++) {
            uint64_t x = 0, y = 0;
            for (int k = 0; k < 8; k++) {
                if (pattern >> k & 1) x |= (uint64_t)byte[(b + (unsigned)k) % 3] << (8 * k);
                if (pattern >> (7 - k) & 1) y |= (uint64_t)byte[(b + 2 * (unsigned)k) % 3] << (8 * k);
            }
            int want_x = coded_tag_reference(x), want_y = coded_tag_reference(y);
            unsigned t0, t1;
            coded_tag2(x, y, &t0, &t1);
            wrong += (coded_tag_by_key(x) != want_x) + (coded_tag(x) != want_x) + ((int)t0 != want_x) + ((int)t1 != want_y);
        }
    return wrong;
}

/* A tag's payload length: 1..8 low bytes, 9..15 the high 16 - tag bytes. */
static const unsigned char coded_len[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 7, 6, 5, 4, 3, 2, 1};
/* The XOR from 8 bytes loaded at its payload (little-endian): (load & mask) << shift. */
#define CODED_LOW(k) (((uint64_t)1 << (8 * (k))) - 1)
static const uint64_t coded_mask[16] = {0, CODED_LOW(1), CODED_LOW(2), CODED_LOW(3), CODED_LOW(4), CODED_LOW(5),
                                        CODED_LOW(6), CODED_LOW(7), ~(uint64_t)0, CODED_LOW(7), CODED_LOW(6),
                                        CODED_LOW(5), CODED_LOW(4), CODED_LOW(3), CODED_LOW(2), CODED_LOW(1)};
#undef CODED_LOW
static const unsigned char coded_shift[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 8, 16, 24, 32, 40, 48, 56};

static void put_coded_slow(writer *o, const double *v, const double *pred, int n)
{
    uint64_t x[CODED_MAX];
    int tag[CODED_MAX];
    size_t len = (size_t)(n + 1) / 2;
    for (int i = 0; i < n; i++) {
        x[i] = f64_bits(v[i]) ^ f64_bits(pred[i]);
        tag[i] = coded_tag(x[i]);
        len += coded_len[tag[i]];
    }
    if (o->pos + len > o->cap) { /* measuring, or out of room: only the size */
        o->pos += len;
        return;
    }
    /* whole 8-byte stores (each value's bytes, then bytes the next one
     * overwrites) straight into the buffer when 8 bytes past the end fit
     * in it, else into a copy: the caller's buffer is written only up to
     * the snapshot's size */
    unsigned char bytes[CODED_MAX / 2 + 1 + 8 * CODED_MAX + 8];
    int direct = SNAP_HOST_LE && o->pos + len + 8 <= o->cap;
    unsigned char *b = direct ? o->buf + o->pos : bytes;
    for (int i = 0; i < n; i += 2) *b++ = (unsigned char)(tag[i] | (i + 1 < n ? tag[i + 1] << 4 : 0));
    for (int i = 0; i < n; i++) {
        if (SNAP_HOST_LE) {
            uint64_t u = tag[i] <= 8 ? x[i] : x[i] >> (8 * (tag[i] - 8));
            memcpy(b, &u, 8);
            b += coded_len[tag[i]];
        } else {
            int from = tag[i] <= 8 ? 0 : tag[i] - 8, to = tag[i] <= 8 ? tag[i] : 8;
            for (int k = from; k < to; k++) *b++ = (unsigned char)(x[i] >> (8 * k));
        }
    }
    if (!direct) memcpy(o->buf + o->pos, bytes, len);
    o->pos += len;
}

/* One value of the inlined path: its payload stored as a whole 8-byte word
 * at *b (the next value's bytes overwrite what is past its length); its tag. */
SNAP_INLINE void put_coded_word(unsigned char **b, uint64_t x, unsigned tag)
{
    uint64_t u = x >> coded_shift[tag];
    memcpy(*b, &u, 8);
    *b += coded_len[tag];
}

/* A group of up to 4 at b, its tags at t (the tags' bytes, then the
 * payloads): the end of its payloads. */
SNAP_INLINE unsigned char *put_coded_group(unsigned char *t, const double *v, const double *pred, int n)
{
    uint64_t x0 = f64_bits(v[0]) ^ f64_bits(pred[0]), x1 = n > 1 ? f64_bits(v[1]) ^ f64_bits(pred[1]) : 0;
    uint64_t x2 = n > 2 ? f64_bits(v[2]) ^ f64_bits(pred[2]) : 0, x3 = n > 3 ? f64_bits(v[3]) ^ f64_bits(pred[3]) : 0;
    unsigned t0, t1, t2 = 0, t3 = 0;
    coded_tag2(x0, x1, &t0, &t1);
    if (n > 2) coded_tag2(x2, x3, &t2, &t3);
    unsigned char *b = t + (n + 1) / 2;
    put_coded_word(&b, x0, t0);
    if (n > 1) put_coded_word(&b, x1, t1);
    if (n > 2) put_coded_word(&b, x2, t2);
    if (n > 3) put_coded_word(&b, x3, t3);
    t[0] = (unsigned char)(t0 | t1 << 4);
    if (n > 2) t[1] = (unsigned char)(t2 | t3 << 4);
    return b;
}


/* The reader's side; every value decoded must be finite. */
static void get_coded_slow(reader *r, double *out, const double *pred, int n, const char *what)
{
    size_t tags = (size_t)(n + 1) / 2;
    if (!need(r, tags, what)) {
        for (int i = 0; i < n; i++) out[i] = 0;
        return;
    }
    const unsigned char *t = r->buf + r->pos;
    size_t total = 0;
    for (int i = 0; i < n; i++) total += coded_len[(t[i >> 1] >> (4 * (i & 1))) & 15];
    if ((n & 1) && (t[n >> 1] >> 4)) { bad(r, "%s: unused tag bits set", what); total = 0; }
    r->pos += tags;
    if (!need(r, total, what)) {
        for (int i = 0; i < n; i++) out[i] = 0;
        return;
    }
    const unsigned char *p = r->buf + r->pos, *end = r->buf + r->size;
    r->pos += total;
    for (int i = 0; i < n; i++) {
        int tag = (t[i >> 1] >> (4 * (i & 1))) & 15, len = coded_len[tag];
        uint64_t x = 0;
        if (SNAP_HOST_LE && end - p >= 8) { /* one load, the value's bytes kept */
            memcpy(&x, p, 8);
            if (len < 8) x &= ((uint64_t)1 << (8 * len)) - 1;
        } else {
            for (int k = 0; k < len; k++) x |= (uint64_t)p[k] << (8 * k);
        }
        if (tag > 8) x <<= 8 * (tag - 8);
        p += len;
        uint64_t bits = x ^ f64_bits(pred[i]);
        memcpy(&out[i], &bits, 8);
        if (coded_tag(x) != tag) { bad(r, "%s: a coded double not in its shortest form", what); break; }
        if (((bits >> 52) & 0x7ff) == 0x7ff) { bad(r, "%s is not finite", what); break; }
    }
    if (r->failed)
        for (int i = 0; i < n; i++) out[i] = 0;
}

/* One value of the inlined path: its payload from one 8-byte load at *p
 * (tag says how many of the bytes are its own, and where they go), the
 * value's bits into *out; *ok cleared unless the tag is the writer's one
 * for the XOR (coded_tag) and the value finite. */
SNAP_INLINE uint64_t get_coded_word(const unsigned char **p, unsigned tag)
{
    uint64_t x;
    memcpy(&x, *p, 8);
    *p += coded_len[tag];
    return (x & coded_mask[tag]) << coded_shift[tag];
}

/* The same, inlined for groups of up to 4, without a bounds check per value
 * while a whole group's largest encoding and 8 bytes more are left (every
 * record but the last few): each value one 8-byte load, its tag checked to
 * be the writer's one for it (coded_tag2, two values at a time) and the
 * value finite. Anything it refuses goes to the checked way above, which
 * finds the same error. */
SNAP_INLINE void get_coded(reader *restrict r, double *out, const double *pred, int n, const char *what)
{
    if (SNAP_HOST_LE && n <= 4 && !r->failed && r->size - r->pos >= 2 + 8 * (size_t)n + 8) {
        const unsigned char *t = r->buf + r->pos, *p = t + (n + 1) / 2;
        unsigned tw = t[0] | (n > 2 ? (unsigned)t[1] << 8 : 0u);
        unsigned t0 = tw & 15, t1 = (tw >> 4) & 15, t2 = (tw >> 8) & 15, t3 = (tw >> 12) & 15;
        uint64_t x0 = get_coded_word(&p, t0), x1 = 0, x2 = 0, x3 = 0;
        if (n > 1) x1 = get_coded_word(&p, t1);
        if (n > 2) x2 = get_coded_word(&p, t2);
        if (n > 3) x3 = get_coded_word(&p, t3);
        unsigned c0, c1, c2 = 0, c3 = 0;
        coded_tag2(x0, x1, &c0, &c1);
        if (n > 2) coded_tag2(x2, x3, &c2, &c3);
        /* (an odd group's last tag byte has its high half unused: zero, the
         * tag of the absent value's 0; for n <= 2 t2 and t3 are 0 as well) */
        unsigned ok = (c0 == t0) & (c1 == t1) & (c2 == t2) & (c3 == t3);
        uint64_t b0 = x0 ^ f64_bits(pred[0]), b1 = n > 1 ? x1 ^ f64_bits(pred[1]) : 0;
        uint64_t b2 = n > 2 ? x2 ^ f64_bits(pred[2]) : 0, b3 = n > 3 ? x3 ^ f64_bits(pred[3]) : 0;
        /* (finite: the exponent not all ones) */
        const uint64_t e = (uint64_t)0x7ff << 52;
        ok &= ((b0 & e) != e) & ((b1 & e) != e) & ((b2 & e) != e) & ((b3 & e) != e);
        memcpy(&out[0], &b0, 8);
        if (n > 1) memcpy(&out[1], &b1, 8);
        if (n > 2) memcpy(&out[2], &b2, 8);
        if (n > 3) memcpy(&out[3], &b3, 8);
        if (ok) {
            r->pos = (size_t)(p - r->buf);
            return;
        }
    }
    get_coded_slow(r, out, pred, n, what);
}

/* One group of n <= 4 coded doubles read from bytes[0, size) against
 * predictions 0, by the inlined way where size leaves it room, else the
 * checked one: the bytes it took, or 0 if refused (tests/test_snapshot.c
 * holds it against the format's definition). */
size_t snapshot_coded_group_read(const unsigned char *bytes, size_t size, int n, double out[4])
{
    static const double zero[4] = {0, 0, 0, 0};
    reader r = {bytes, size, 0, NULL, 0, 0, SNAP_VERSION, 0, NULL, 0};
    if (n < 1 || n > 4) return 0;
    get_coded(&r, out, zero, n, "group");
    return r.failed ? 0 : r.pos;
}

/* One varint in [lo, hi] from bytes[0, size) as the records read it
 * (tests/test_snapshot.c): the bytes it took, 0 if refused. */
size_t snapshot_small_read(const unsigned char *bytes, size_t size, int64_t lo, int64_t hi, int is_signed, int *out)
{
    reader r = {bytes, size, 0, NULL, 0, 0, SNAP_VERSION, 0, NULL, 0};
    *out = get_small(&r, lo, hi, is_signed, "varint");
    return r.failed ? 0 : r.pos;
}

SNAP_INLINE vec3 get_coded_v3(reader *r, vec3 pred, const char *what)
{
    double a[3], p[3] = {pred.x, pred.y, pred.z};
    get_coded(r, a, p, 3, what);
    return v3(a[0], a[1], a[2]);
}

SNAP_INLINE quat get_coded_q(reader *r, quat pred, const char *what)
{
    double a[4], p[4] = {pred.w, pred.x, pred.y, pred.z};
    get_coded(r, a, p, 4, what);
    quat q = {a[0], a[1], a[2], a[3]};
    return q;
}

SNAP_INLINE double get_coded1(reader *r, double pred, const char *what)
{
    double v;
    get_coded(r, &v, &pred, 1, what);
    return v;
}

/* ---- records: one bounds check each --------------------------------------------- */

/* The most bytes a body or contact record takes (a contact's: ids, head, 3
 * varints, 8 groups of 3 or 4 coded doubles, 4 points of a varint and 4
 * groups; every varint 10 bytes at most, a group of n 1 + n / 2 + 8 n), and
 * the 8 bytes an inlined payload store writes past its value. */
#define SNAP_RECORD_MAX 1024
typedef char snapshot_record_max_holds[6 * 10 + 8 * 35 + MANIFOLD_MAX_POINTS * (10 + 4 * 35) + 8 <= SNAP_RECORD_MAX ? 1 : -1];

/* Where a record's bytes go: straight into the buffer when its largest
 * size fits there (it starts below `direct`, record_room), else into
 * scratch (measuring, the last records), which record_end copies out as far
 * as the capacity goes. Within a record the writes are unchecked
 * (cur_varint, cur_coded). The record loops keep the position in a local
 * (the byte stores cannot reach it, so it stays in a register). */
static size_t record_room(const writer *o)
{
    return o->buf && o->cap >= SNAP_RECORD_MAX ? o->cap - SNAP_RECORD_MAX + 1 : 0;
}

SNAP_INLINE unsigned char *record_begin(unsigned char *buf, size_t pos, size_t direct, unsigned char *scratch)
{
    return pos < direct ? buf + pos : scratch;
}

/* The position after the record [start, end). */
SNAP_INLINE size_t record_end(unsigned char *buf, size_t pos, size_t cap, const unsigned char *start, const unsigned char *end,
                              const unsigned char *scratch)
{
    size_t len = (size_t)(end - start);
    if (start == scratch && pos < cap) memcpy(buf + pos, scratch, len < cap - pos ? len : cap - pos);
    return pos + len;
}

static unsigned char *cur_varint_slow(unsigned char *wp, uint64_t v)
{
    while (v >= 0x80) { *wp++ = (unsigned char)((v & 0x7f) | 0x80); v >>= 7; }
    *wp++ = (unsigned char)v;
    return wp;
}

SNAP_INLINE unsigned char *cur_varint(unsigned char *wp, uint64_t v)
{
    if (v < 0x80) {
        wp[0] = (unsigned char)v;
        return wp + 1;
    }
    if (v < (1u << 14)) {
        wp[0] = (unsigned char)((v & 0x7f) | 0x80);
        wp[1] = (unsigned char)(v >> 7);
        return wp + 2;
    }
    return cur_varint_slow(wp, v);
}

/* A group of coded doubles at wp (room for its largest size and 8 more). */
SNAP_INLINE unsigned char *cur_coded(unsigned char *wp, const double *v, const double *pred, int n)
{
    if (!SNAP_HOST_LE || n > 4) { /* (portable: through a writer over the same bytes) */
        writer o = {wp, (size_t)(n + 1) / 2 + 8 * (size_t)n, 0, NULL};
        put_coded_slow(&o, v, pred, n);
        return wp + o.pos;
    }
    return put_coded_group(wp, v, pred, n);
}

SNAP_INLINE unsigned char *cur_coded_v3(unsigned char *wp, vec3 v, vec3 pred)
{
    double a[3] = {v.x, v.y, v.z}, p[3] = {pred.x, pred.y, pred.z};
    return cur_coded(wp, a, p, 3);
}

SNAP_INLINE unsigned char *cur_coded_q(unsigned char *wp, quat q, quat pred)
{
    double a[4] = {q.w, q.x, q.y, q.z}, p[4] = {pred.w, pred.x, pred.y, pred.z};
    return cur_coded(wp, a, p, 4);
}

SNAP_INLINE unsigned char *cur_coded1(unsigned char *wp, double v, double pred) { return cur_coded(wp, &v, &pred, 1); }

static int v3_is_zero(vec3 v) { return f64_bits(v.x) == 0 && f64_bits(v.y) == 0 && f64_bits(v.z) == 0; }
static int same_bits(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }

/* ---- checksum: 64-bit, four independent lanes of eight bytes ------------------- */

/* A lane's step is a multiply and a shift that the next word waits for (one
 * lane: 5 cycles per 8 bytes, half a millisecond for a 10,000-body world);
 * four lanes over 32-byte blocks run side by side, then fold into one. */
#define SUM_MUL 0xff51afd7ed558ccdULL
static uint64_t sum_word(const unsigned char *p)
{
    uint64_t v = 0;
    if (SNAP_HOST_LE) memcpy(&v, p, 8);
    else for (int k = 7; k >= 0; k--) v = (v << 8) | p[k];
    return v;
}
static uint64_t sum_step(uint64_t h, uint64_t v)
{
    h = (h ^ v) * SUM_MUL;
    return h ^ (h >> 29);
}

static uint64_t checksum(const unsigned char *p, size_t n)
{
    uint64_t lane[4];
    for (int k = 0; k < 4; k++) lane[k] = 0x9e3779b97f4a7c15ULL ^ (uint64_t)n ^ ((uint64_t)k << 56);
    size_t i = 0;
    for (; i + 32 <= n; i += 32)
        for (int k = 0; k < 4; k++) lane[k] = sum_step(lane[k], sum_word(p + i + 8 * (size_t)k));
    uint64_t h = lane[0];
    for (int k = 1; k < 4; k++) h = sum_step(h, lane[k]);
    for (; i + 8 <= n; i += 8) h = sum_step(h, sum_word(p + i));
    for (; i < n; i++) {
        h = (h ^ p[i]) * 0xc4ceb9fe1a85ec53ULL;
        h ^= h >> 31;
    }
    return h;
}

/* ---- settings -------------------------------------------------------------------- */

/* The def's fields in declaration order; the callback and its context are
 * pointers into the writer's process and are not written. */
#define DEF_FIELDS(F, I, V)                                                                                   \
    V(gravity) I(substeps) I(iterations) I(relax_iterations) I(position_correction) I(warm_starting)           \
    F(restitution_threshold) F(contact_hertz) F(contact_damping_ratio) F(contact_push_max_velocity)           \
    F(baumgarte) F(linear_slop) F(speculative_distance) I(contact_model) F(penalty_stiffness)                 \
    F(penalty_damping) I(penalty_implicit) I(shock_propagation) I(enable_friction) I(enable_restitution)      \
    I(enable_sleep) I(enable_continuous) F(sleep_time) F(sleep_linear_velocity) F(sleep_angular_velocity)     \
    F(max_linear_speed) F(max_angular_speed) I(body_capacity) F(contact_reuse_distance) F(hit_event_threshold)

/* A field appended to carom_world_def must be added above (and to
 * docs/snapshot.md): this stops the build until it is. The task hooks
 * (worker_count .. task_context, the last fields) are not written either:
 * they belong to the writer's process, and a worker count without its
 * hooks would be refused; a restored world runs on the calling thread until
 * the host sets its own hooks. */
typedef char snapshot_def_fields_cover_the_def
    [offsetof(carom_world_def, hit_event_threshold) + sizeof(double) == offsetof(carom_world_def, worker_count) &&
     offsetof(carom_world_def, task_context) + sizeof(void *) == sizeof(carom_world_def) ? 1 : -1];

static void write_def(writer *o, const carom_world_def *d)
{
#define WF(f) put_f64(o, d->f);
#define WI(f) put_i32(o, (int)d->f);
#define WV(f) put_f64(o, d->f.x); put_f64(o, d->f.y); put_f64(o, d->f.z);
    DEF_FIELDS(WF, WI, WV)
#undef WF
#undef WI
#undef WV
}

static void read_def(reader *r, carom_world_def *d)
{
    *d = carom_world_def_default();
#define RF(f) d->f = get_f64(r, "setting " #f);
#define RI(f) d->f = get_i32(r, "setting " #f);
#define RV(f) d->f.x = get_f64(r, "setting " #f); d->f.y = get_f64(r, "setting " #f); d->f.z = get_f64(r, "setting " #f);
    DEF_FIELDS(RF, RI, RV)
#undef RF
#undef RI
#undef RV
}

/* ---- shapes: one case per shape type ----------------------------------------------- */

static void write_shape(writer *o, const shape *s)
{
    put_u8(o, (unsigned)s->type);
    switch (s->type) {
    case SHAPE_SPHERE: put_f64(o, s->radius); break;
    case SHAPE_BOX: put_v3(o, s->half_extents); break;
    case SHAPE_CAPSULE:
    case SHAPE_CYLINDER: put_f64(o, s->radius); put_f64(o, s->half_height); break;
    case SHAPE_PLANE: put_v3(o, s->plane_normal); put_f64(o, s->plane_offset); break;
    case SHAPE_HULL: {
        const hull *h = s->hull;
        int nfv = 0;
        for (int f = 0; f < h->face_count; f++)
            if (h->faces[f].first + h->faces[f].count > nfv) nfv = h->faces[f].first + h->faces[f].count;
        put_i32(o, h->vertex_count);
        put_i32(o, h->face_count);
        put_i32(o, nfv);
        put_i32(o, h->edge_count);
        for (int i = 0; i < h->vertex_count; i++) put_v3(o, h->vertices[i]);
        for (int f = 0; f < h->face_count; f++) {
            put_v3(o, h->faces[f].normal);
            put_f64(o, h->faces[f].offset);
            put_i32(o, h->faces[f].first);
            put_i32(o, h->faces[f].count);
        }
        for (int i = 0; i < nfv; i++) put_i32(o, h->face_vertices[i]);
        for (int e = 0; e < h->edge_count; e++) { put_i32(o, h->edges[e][0]); put_i32(o, h->edges[e][1]); }
        put_v3(o, h->centroid);
        put_f64(o, h->volume);
        put_m3(o, h->unit_inertia);
        break;
    }
    case SHAPE_MESH: {
        /* whole, tree included: rebuilding it could order the triangles
         * differently, and their order is what contacts and rays report */
        const tri_mesh *m = s->mesh;
        put_u8(o, (unsigned)m->two_sided);
        put_i32(o, m->vertex_count);
        put_i32(o, m->triangle_count);
        put_i32(o, m->node_count);
        for (int i = 0; i < m->vertex_count; i++) put_v3(o, m->vertices[i]);
        for (int t = 0; t < m->triangle_count; t++) {
            for (int k = 0; k < 3; k++) put_i32(o, m->triangles[t][k]);
            put_i32(o, m->source_index[t]);
            put_u8(o, m->active[t]);
        }
        for (int i = 0; i < m->node_count; i++) {
            put_v3(o, m->nodes[i].box.lo);
            put_v3(o, m->nodes[i].box.hi);
            put_i32(o, m->nodes[i].first);
            put_i32(o, m->nodes[i].count);
        }
        break;
    }
    case SHAPE_HEIGHTFIELD: {
        const height_field *h = s->field;
        int cells = (h->rows - 1) * (h->columns - 1), holes = 0;
        for (int i = 0; i < cells; i++) holes += h->hole[i] != 0;
        put_i32(o, h->rows);
        put_i32(o, h->columns);
        put_f64(o, h->cell_x);
        put_f64(o, h->cell_y);
        for (int i = 0; i < h->rows * h->columns; i++) put_f64(o, h->heights[i]);
        put_i32(o, holes);
        for (int i = 0; i < cells; i++)
            if (h->hole[i]) put_i32(o, i);
        break;
    }
    case SHAPE_COMPOUND: {
        const compound *c = s->compound;
        put_i32(o, c->count);
        for (int i = 0; i < c->count; i++) {
            put_v3(o, c->poses[i].p);
            put_q(o, c->poses[i].q);
            put_f64(o, c->friction[i]);
            put_f64(o, c->restitution[i]);
            put_f64(o, c->density[i]);
            put_f64(o, c->rolling_resistance[i]);
            put_u8(o, (unsigned)c->combine[i]);
            write_shape(o, &c->children[i]);
        }
        break;
    }
    }
}

static int length_ok(double x) { return x >= RANGE_LENGTH_MIN && x <= RANGE_LENGTH_MAX; }

static hull *read_hull(reader *r)
{
    int nv = get_i32(r, "hull vertex count"), nf = get_i32(r, "hull face count");
    int nfv = get_i32(r, "hull face vertex count"), ne = get_i32(r, "hull edge count");
    if (r->failed) return NULL;
    if (nv < 4 || nv > HULL_MAX_VERTICES || nf < 4 || nf > HULL_MAX_FACES || nfv < 3 * nf ||
        nfv > HULL_MAX_FACE_VERTICES || ne < 6 || ne > HULL_MAX_FACE_VERTICES / 2)
        return bad(r, "hull counts (%d vertices, %d faces, %d face vertices, %d edges) are out of range", nv, nf, nfv, ne),
               NULL;
    size_t bytes = (size_t)nv * 24 + (size_t)nf * 40 + (size_t)nfv * 4 + (size_t)ne * 8 + 104;
    if (!need(r, bytes, "hull")) return NULL;
    hull *h = calloc(1, sizeof *h);
    if (!h) return no_memory(r), NULL;
    h->vertices = malloc(sizeof *h->vertices * (size_t)nv);
    h->faces = malloc(sizeof *h->faces * (size_t)nf);
    h->face_vertices = malloc(sizeof *h->face_vertices * (size_t)nfv);
    h->edges = malloc(sizeof *h->edges * (size_t)ne);
    if (!h->vertices || !h->faces || !h->face_vertices || !h->edges) { hull_free(h); return no_memory(r), NULL; }
    h->vertex_count = nv;
    h->face_count = nf;
    h->edge_count = ne;
    for (int i = 0; i < nv; i++) {
        h->vertices[i] = get_v3(r, "hull vertex");
        if (!(fabs(h->vertices[i].x) <= RANGE_LENGTH_MAX && fabs(h->vertices[i].y) <= RANGE_LENGTH_MAX &&
              fabs(h->vertices[i].z) <= RANGE_LENGTH_MAX) && !r->failed)
            bad(r, "hull vertex %d is beyond 1e6 m", i);
    }
    for (int f = 0; f < nf && !r->failed; f++) {
        hull_face *hf = &h->faces[f];
        hf->normal = get_v3(r, "hull face normal");
        hf->offset = get_f64(r, "hull face offset");
        hf->first = get_i32(r, "hull face first");
        hf->count = get_i32(r, "hull face count");
        if (!r->failed && (hf->count < 3 || hf->first < 0 || hf->first > nfv - hf->count))
            bad(r, "hull face %d has %d vertices from index %d, of %d", f, hf->count, hf->first, nfv);
        if (!r->failed && fabs(v3_len(hf->normal) - 1.0) > 1e-6) bad(r, "hull face %d normal is not unit", f);
    }
    int total = 0, used = 0;
    for (int f = 0; f < nf && !r->failed; f++) {
        total += h->faces[f].count;
        if (h->faces[f].first + h->faces[f].count > used) used = h->faces[f].first + h->faces[f].count;
    }
    /* the writer writes exactly the face vertices the faces use */
    if (!r->failed && used != nfv) bad(r, "hull has %d face vertices, its faces use %d", nfv, used);
    if (!r->failed && total > HULL_MAX_FACE_VERTICES) bad(r, "hull faces hold %d vertices, at most %d", total, HULL_MAX_FACE_VERTICES);
    for (int i = 0; i < nfv && !r->failed; i++) {
        h->face_vertices[i] = get_i32(r, "hull face vertex");
        if (!r->failed && (h->face_vertices[i] < 0 || h->face_vertices[i] >= nv)) bad(r, "hull face vertex %d out of range", i);
    }
    for (int e = 0; e < ne && !r->failed; e++)
        for (int k = 0; k < 2; k++) {
            h->edges[e][k] = get_i32(r, "hull edge");
            if (!r->failed && (h->edges[e][k] < 0 || h->edges[e][k] >= nv)) bad(r, "hull edge %d out of range", e);
        }
    h->centroid = get_v3(r, "hull centroid");
    h->volume = get_f64(r, "hull volume");
    h->unit_inertia = get_m3(r, "hull inertia");
    if (!r->failed && !(h->volume > 0)) bad(r, "hull volume is not positive");
    if (r->failed) { hull_free(h); return NULL; }
    return h;
}


/* Every index is checked: triangles name vertices, leaves name triangles, and
 * every node but the root is the child of exactly one inner node above it,
 * so the tree is a tree and its walks end. */
static tri_mesh *read_mesh(reader *r)
{
    int two_sided = (int)get_u8(r, "mesh two-sided flag");
    int nv = get_i32(r, "mesh vertex count"), nt = get_i32(r, "mesh triangle count"), nn = get_i32(r, "mesh node count");
    if (r->failed) return NULL;
    if (two_sided > 1 || nv < 3 || nv > 100000000 || nt < 1 || nt > 100000000 || nn < 1 || nn > 2 * nt)
        return bad(r, "mesh counts (%d vertices, %d triangles, %d nodes) are out of range", nv, nt, nn), NULL;
    if (!need(r, (size_t)nv * 24 + (size_t)nt * 17 + (size_t)nn * 56, "mesh")) return NULL;
    tri_mesh *m = calloc(1, sizeof *m);
    if (!m) return no_memory(r), NULL;
    m->two_sided = two_sided;
    m->vertex_count = nv;
    m->triangle_count = nt;
    m->node_count = nn;
    m->vertices = malloc(sizeof *m->vertices * (size_t)nv);
    m->triangles = malloc(sizeof *m->triangles * (size_t)nt);
    m->source_index = malloc(sizeof *m->source_index * (size_t)nt);
    m->active = malloc((size_t)nt);
    m->nodes = malloc(sizeof *m->nodes * (size_t)nn);
    unsigned char *parents = calloc((size_t)nn, 1);
    if (!m->vertices || !m->triangles || !m->source_index || !m->active || !m->nodes || !parents) {
        free(parents);
        mesh_free(m);
        return no_memory(r), NULL;
    }
    for (int i = 0; i < nv && !r->failed; i++) {
        m->vertices[i] = get_v3(r, "mesh vertex");
        vec3 v = m->vertices[i];
        if (!r->failed && !within_cube(v, RANGE_LENGTH_MAX))
            bad(r, "mesh vertex %d is beyond 1e6 m", i);
    }
    for (int t = 0; t < nt && !r->failed; t++) {
        for (int k = 0; k < 3; k++) m->triangles[t][k] = get_i32(r, "mesh triangle");
        m->source_index[t] = get_i32(r, "mesh triangle source");
        m->active[t] = (uint8_t)get_u8(r, "mesh triangle edges");
        const int *v = m->triangles[t];
        if (!r->failed && (v[0] < 0 || v[0] >= nv || v[1] < 0 || v[1] >= nv || v[2] < 0 || v[2] >= nv || v[0] == v[1] ||
                           v[1] == v[2] || v[2] == v[0] || m->source_index[t] < 0 || m->active[t] > 7))
            bad(r, "mesh triangle %d has bad vertices, source index or edge bits", t);
    }
    for (int i = 0; i < nn && !r->failed; i++) {
        mesh_node *nd = &m->nodes[i];
        nd->box.lo = get_v3(r, "mesh node");
        nd->box.hi = get_v3(r, "mesh node");
        nd->first = get_i32(r, "mesh node");
        nd->count = get_i32(r, "mesh node");
        if (r->failed) break;
        if (!(nd->box.lo.x <= nd->box.hi.x && nd->box.lo.y <= nd->box.hi.y && nd->box.lo.z <= nd->box.hi.z))
            bad(r, "mesh node %d bounds are inverted", i);
        else if (nd->count > 0 ? nd->first < 0 || nd->first > nt - nd->count
                               : nd->count < 0 || nd->first <= i || nd->first > nn - 2 || parents[nd->first] || parents[nd->first + 1])
            bad(r, "mesh node %d has children or triangles out of range", i);
        else if (nd->count == 0)
            parents[nd->first] = parents[nd->first + 1] = 1;
    }
    for (int i = 1; i < nn && !r->failed; i++)
        if (!parents[i]) bad(r, "mesh node %d is in no tree", i);
    free(parents);
    if (r->failed) { mesh_free(m); return NULL; }
    return m;
}

/* Built again by heightfield_build, which checks every value. */
static height_field *read_field(reader *r)
{
    int rows = get_i32(r, "height field rows"), columns = get_i32(r, "height field columns");
    double cx = get_f64(r, "height field cell"), cy = get_f64(r, "height field cell");
    if (r->failed) return NULL;
    if (rows < 2 || columns < 2 || (double)rows * columns > 1e8)
        return bad(r, "height field of %d x %d points", rows, columns), NULL;
    size_t points = (size_t)rows * (size_t)columns;
    if (!need(r, points * 8 + 4, "height field")) return NULL;
    double *heights = malloc(sizeof *heights * points);
    if (!heights) return no_memory(r), NULL;
    for (size_t i = 0; i < points; i++) heights[i] = get_f64(r, "height");
    int cells = (rows - 1) * (columns - 1);
    int holes = get_count(r, 4, cells, "height field hole count");
    int *hole = malloc(sizeof *hole * (size_t)(holes > 0 ? holes : 1));
    if (!hole) { free(heights); return no_memory(r), NULL; }
    for (int i = 0; i < holes; i++) {
        hole[i] = get_i32(r, "height field hole");
        if (!r->failed && i > 0 && hole[i] <= hole[i - 1]) bad(r, "height field holes are not increasing");
    }
    height_field *h = NULL;
    if (!r->failed) {
        char why[160];
        h = heightfield_build(heights, rows, columns, cx, cy, hole, holes, why, (int)sizeof why);
        if (!h) bad(r, "%s", why);
    }
    free(heights);
    free(hole);
    return h;
}

static int read_shape(reader *r, shape *s, int body_type, int child);

static compound *read_compound(reader *r)
{
    int n = get_i32(r, "compound child count");
    if (r->failed) return NULL;
    if (n < 1 || n > 256) return bad(r, "compound of %d children", n), NULL;
    if (!need(r, (size_t)n * 99, "compound")) return NULL;
    compound *c = compound_alloc(n);
    if (!c) return no_memory(r), NULL;
    for (int i = 0; i < n; i++) {
        c->poses[i].p = get_v3(r, "compound child pose");
        c->poses[i].q = get_q(r, "compound child pose");
        c->friction[i] = get_f64(r, "compound child friction");
        c->restitution[i] = get_f64(r, "compound child restitution");
        c->density[i] = get_f64(r, "compound child density");
        c->rolling_resistance[i] = get_f64(r, "compound child rolling resistance");
        c->combine[i] = (int)get_u8(r, "compound child combine mode");
        if (r->failed) break;
        vec3 p = c->poses[i].p;
        quat q = c->poses[i].q;
        if (!within_cube(p, RANGE_LENGTH_MAX) ||
            not_unit(q)) {
            bad(r, "compound child %d pose out of range", i);
            break;
        }
        if (!(c->friction[i] >= 0 && c->friction[i] <= RANGE_FRICTION_MAX && c->restitution[i] >= 0 &&
              c->restitution[i] <= 1 && c->density[i] >= RANGE_DENSITY_MIN && c->density[i] <= RANGE_DENSITY_MAX &&
              c->rolling_resistance[i] >= 0 && c->rolling_resistance[i] <= RANGE_FRICTION_MAX && c->combine[i] <= CAROM_COMBINE_MAX)) {
            bad(r, "compound child %d material out of range", i);
            break;
        }
        c->count = i + 1; /* its shape is owned from here: freed on a failure */
        if (!read_shape(r, &c->children[i], CAROM_BODY_DYNAMIC, 1)) break;
    }
    if (r->failed) { compound_free(c); return NULL; }
    return c;
}

static int read_shape(reader *r, shape *s, int body_type, int child)
{
    memset(s, 0, sizeof *s);
    s->type = (int)get_u8(r, "shape type");
    if (r->failed) return 0;
    switch (s->type) {
    case SHAPE_SPHERE:
        s->radius = get_f64(r, "sphere radius");
        if (!r->failed && !length_ok(s->radius)) return bad(r, "sphere radius %g is outside [1e-6, 1e6] m", s->radius);
        break;
    case SHAPE_BOX:
        s->half_extents = get_v3(r, "box half extents");
        if (!r->failed && !(length_ok(s->half_extents.x) && length_ok(s->half_extents.y) && length_ok(s->half_extents.z)))
            return bad(r, "box half extents are outside [1e-6, 1e6] m");
        break;
    case SHAPE_CAPSULE:
    case SHAPE_CYLINDER:
        s->radius = get_f64(r, "radius");
        s->half_height = get_f64(r, "half height");
        if (!r->failed && !(length_ok(s->radius) && length_ok(s->half_height)))
            return bad(r, "capsule or cylinder size is outside [1e-6, 1e6] m");
        break;
    case SHAPE_PLANE:
        s->plane_normal = get_v3(r, "plane normal");
        s->plane_offset = get_f64(r, "plane offset");
        if (!r->failed && fabs(v3_len(s->plane_normal) - 1.0) > 1e-9) return bad(r, "plane normal is not unit");
        if (!r->failed && !(fabs(s->plane_offset) <= RANGE_COORDINATE_MAX)) return bad(r, "plane offset beyond 1e12 m");
        if (!r->failed && (child || body_type != CAROM_BODY_STATIC)) return bad(r, "a plane on a body that is not static");
        break;
    case SHAPE_HULL:
        s->hull = read_hull(r);
        break;
    case SHAPE_MESH:
    case SHAPE_HEIGHTFIELD:
        if (child) return bad(r, "a compound child that is a mesh or height field");
        if (body_type == CAROM_BODY_DYNAMIC) return bad(r, "a mesh or height field on a dynamic body");
        if (s->type == SHAPE_MESH) s->mesh = read_mesh(r);
        else s->field = read_field(r);
        break;
    case SHAPE_COMPOUND:
        if (child) return bad(r, "a compound inside a compound");
        s->compound = read_compound(r);
        break;
    default:
        return bad(r, "unknown shape type %d", s->type);
    }
    return !r->failed;
}

/* ---- the snapshot ------------------------------------------------------------------- */

#define BODY_KNOWN_FLAGS (BODY_LOCK_ROTATION | BODY_LOCK_PLANE | BODY_BULLET | BODY_AWAKE | BODY_ENABLE_SLEEP | BODY_HAS_FORCE | \
                          BODY_SENSOR)
/* the flags a body's class holds; the rest are per body */
#define BODY_STATE_FLAGS (BODY_AWAKE | BODY_HAS_FORCE)
#define CONTACT_KNOWN_FLAGS \
    (CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_SIM | CONTACT_REUSABLE | CONTACT_APART | CONTACT_ANY_TOUCHING)

/* A body's class: everything most bodies share with others (type, shape, mass
 * properties, material, filter), written once in a table and named by index. */
static void write_class(writer *o, const body_store *s, int i)
{
    put_u8(o, (unsigned)s->type[i]);
    put_u32(o, s->flags[i] & ~(uint32_t)BODY_STATE_FLAGS);
    put_v3(o, s->local_center[i]);
    put_f64(o, s->mass[i]);
    put_m3(o, s->inertia_local[i]);
    put_f64(o, s->friction[i]);
    put_f64(o, s->restitution[i]);
    put_f64(o, s->linear_damping[i]);
    put_f64(o, s->angular_damping[i]);
    put_f64(o, s->gravity_scale[i]);
    put_v3(o, s->plane_normal[i]);
    put_u64(o, s->category[i]);
    put_u64(o, s->filter_mask[i]);
    put_i32(o, s->group[i]);
    put_f64(o, s->force_threshold[i]);
    put_f64(o, s->rolling_resistance[i]);
    put_u8(o, (unsigned)s->combine[i]);
    write_shape(o, &s->shapes[i]);
}

/* (the class table's own hash, not part of the format: eight bytes a step) */
static uint64_t hash_bytes(const unsigned char *p, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ULL ^ (uint64_t)n;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t v;
        memcpy(&v, p + i, 8);
        h = (h ^ v) * 0xff51afd7ed558ccdULL;
        h ^= h >> 32;
    }
    for (; i < n; i++) h = (h ^ p[i]) * 0x100000001b3ULL;
    return h;
}

/* The class table: classes in order of first use, each body's class index. */
typedef struct class_table {
    unsigned char *bytes;   /* the classes, one after another */
    size_t size;
    size_t *start;          /* per class: offset in bytes (count + 1 entries) */
    int count;
    int *of_body;           /* per slot */
} class_table;

static void class_table_free(class_table *t)
{
    free(t->bytes);
    free(t->start);
    free(t->of_body);
}

/* Whether bodies i and j write the same class bytes (write_class): every
 * field it writes equal to the bit, the shape a primitive or a hull with
 * the same numbers. 0 for meshes, height fields and compounds (the caller
 * writes those and compares the bytes). */
static int same_bits_v3(vec3 a, vec3 b) { return same_bits(&a, &b, sizeof a); }
static int same_hull(const hull *a, const hull *b)
{
    if (a == b) return 1;
    if (a->vertex_count != b->vertex_count || a->face_count != b->face_count || a->edge_count != b->edge_count ||
        !same_bits(a->vertices, b->vertices, sizeof *a->vertices * (size_t)a->vertex_count) ||
        !same_bits_v3(a->centroid, b->centroid) || f64_bits(a->volume) != f64_bits(b->volume) ||
        !same_bits(&a->unit_inertia, &b->unit_inertia, sizeof a->unit_inertia) ||
        !same_bits(a->edges, b->edges, sizeof *a->edges * (size_t)a->edge_count))
        return 0;
    int nfv = 0;
    for (int f = 0; f < a->face_count; f++) {
        const hull_face *x = &a->faces[f], *y = &b->faces[f];
        if (!same_bits_v3(x->normal, y->normal) || f64_bits(x->offset) != f64_bits(y->offset) || x->first != y->first ||
            x->count != y->count)
            return 0;
        if (x->first + x->count > nfv) nfv = x->first + x->count;
    }
    return same_bits(a->face_vertices, b->face_vertices, sizeof *a->face_vertices * (size_t)nfv);
}
static int same_shape(const shape *a, const shape *b)
{
    if (a->type != b->type) return 0;
    switch (a->type) {
    case SHAPE_SPHERE: return f64_bits(a->radius) == f64_bits(b->radius);
    case SHAPE_BOX: return same_bits_v3(a->half_extents, b->half_extents);
    case SHAPE_CAPSULE:
    case SHAPE_CYLINDER: return f64_bits(a->radius) == f64_bits(b->radius) && f64_bits(a->half_height) == f64_bits(b->half_height);
    case SHAPE_PLANE: return same_bits_v3(a->plane_normal, b->plane_normal) && f64_bits(a->plane_offset) == f64_bits(b->plane_offset);
    case SHAPE_HULL: return same_hull(a->hull, b->hull);
    default: return 0;
    }
}
static int same_class(const body_store *s, int i, int j)
{
    /* (the cheap fields that tell classes apart first: the shape's type, the mass) */
    return s->type[i] == s->type[j] && s->shapes[i].type == s->shapes[j].type && f64_bits(s->mass[i]) == f64_bits(s->mass[j]) &&
           ((s->flags[i] ^ s->flags[j]) & ~(uint32_t)BODY_STATE_FLAGS) == 0 &&
           same_bits_v3(s->local_center[i], s->local_center[j]) && f64_bits(s->mass[i]) == f64_bits(s->mass[j]) &&
           same_bits(&s->inertia_local[i], &s->inertia_local[j], sizeof(mat3)) &&
           f64_bits(s->friction[i]) == f64_bits(s->friction[j]) && f64_bits(s->restitution[i]) == f64_bits(s->restitution[j]) &&
           f64_bits(s->linear_damping[i]) == f64_bits(s->linear_damping[j]) &&
           f64_bits(s->angular_damping[i]) == f64_bits(s->angular_damping[j]) &&
           f64_bits(s->gravity_scale[i]) == f64_bits(s->gravity_scale[j]) && same_bits_v3(s->plane_normal[i], s->plane_normal[j]) &&
           s->category[i] == s->category[j] && s->filter_mask[i] == s->filter_mask[j] && s->group[i] == s->group[j] &&
           f64_bits(s->force_threshold[i]) == f64_bits(s->force_threshold[j]) &&
           f64_bits(s->rolling_resistance[i]) == f64_bits(s->rolling_resistance[j]) && s->combine[i] == s->combine[j] &&
           same_shape(&s->shapes[i], &s->shapes[j]);
}

/* The last few classes seen, by a body of each: most bodies match one of
 * them field by field (no bytes written, no hash) */
#define RECENT_CLASSES 8

static int build_classes(const body_store *s, class_table *t)
{
    int recent[RECENT_CLASSES], recent_count = 0, recent_next = 0;
    memset(t, 0, sizeof *t);
    int n = s->count;
    size_t total = 4096; /* grown as the distinct classes need (each written once) */
    int cap = 16;
    while (cap < 2 * n) cap *= 2;
    int *slots = malloc(sizeof *slots * (size_t)cap);
    uint64_t *hashes = malloc(sizeof *hashes * (size_t)cap);
    t->bytes = malloc(total > 0 ? total : 1);
    t->start = malloc(sizeof *t->start * (size_t)(n + 1));
    t->of_body = malloc(sizeof *t->of_body * (size_t)(n > 0 ? n : 1));
    if (!slots || !hashes || !t->bytes || !t->start || !t->of_body) {
        free(slots);
        free(hashes);
        class_table_free(t);
        return 0;
    }
    for (int k = 0; k < cap; k++) slots[k] = -1;
    t->start[0] = 0;
    for (int i = 0; i < n; i++) {
        int hit = -1;
        for (int r = 0; r < recent_count && hit < 0; r++)
            if (same_class(s, i, recent[r])) hit = recent[r];
        if (hit >= 0) {
            t->of_body[i] = t->of_body[hit];
            continue;
        }
        recent[recent_next] = i;
        recent_next = (recent_next + 1) % RECENT_CLASSES;
        if (recent_count < RECENT_CLASSES) recent_count++;
        size_t at = t->start[t->count];
        writer o = {t->bytes, total, at, NULL};
        write_class(&o, s, i);
        if (o.pos > total) {
            size_t grown = total;
            while (grown < o.pos) grown *= 2;
            unsigned char *more = realloc(t->bytes, grown);
            if (!more) {
                free(slots);
                free(hashes);
                class_table_free(t);
                return 0;
            }
            t->bytes = more;
            total = grown;
            o = (writer){t->bytes, total, at, NULL};
            write_class(&o, s, i);
        }
        size_t len = o.pos - at;
        uint64_t h = hash_bytes(t->bytes + at, len);
        int k = (int)(h & (uint64_t)(cap - 1));
        while (slots[k] >= 0) {
            int c = slots[k];
            if (hashes[k] == h && t->start[c + 1] - t->start[c] == len && memcmp(t->bytes + t->start[c], t->bytes + at, len) == 0)
                break;
            k = (k + 1) & (cap - 1);
        }
        if (slots[k] < 0) {
            slots[k] = t->count;
            hashes[k] = h;
            t->start[++t->count] = at + len;
        }
        t->of_body[i] = slots[k];
    }
    t->size = t->start[t->count];
    free(slots);
    free(hashes);
    return 1;
}

/* What the reader predicts a body's fat bounds to be: its bounds now, fattened
 * as a body at rest is (most bodies in a snapshot last moved their proxy
 * where they still are, or near it; the bounds at the pose of the body's
 * last pair test, fattened as collision.c does, predict a settled pile's
 * worse: 366 against 368 bytes per body). */
static aabb predicted_fat_box(const carom_world *w, int slot)
{
    return world_body_fat_aabb(w, slot, WORLD_AABB_MARGIN);
}

/* A body's previous pose (the start of the last step). */
static xform previous_pose(const body_store *s, int i)
{
    xform x = {s->previous_origin[i], s->previous_rotation[i]};
    return x;
}

/* What the reader predicts a body's collided pose to be: an awake body's
 * last pair test was at the start of the last step (its previous pose); a
 * body that fell asleep had its pairs settled at the pose it rests at
 * (collision.c, world_settle_body), x. */
static xform collided_guess(const body_store *s, int i, xform x)
{
    return (s->flags[i] & BODY_AWAKE) ? previous_pose(s, i) : x;
}

/* body record bits */
enum {
    REC_AWAKE = 1, REC_FORCE_FLAG = 2, REC_MOVED = 4, REC_VELOCITY = 8, REC_SPIN = 16, REC_FORCE = 32,
    REC_SLEEP_TIME = 64, REC_PREVIOUS = 128, REC_FAT = 256, REC_TORQUE = 512, REC_COLLIDED = 1024, REC_ALL = 2047
};

/* A body's record bits, from its state: the writer's, and what the reader
 * checks it read (one encoding per state). */
/* What the reader predicts a body's sleep timer to be: a sleeping body's is
 * the world's threshold (what falling asleep and body_set_awake(0) set), an
 * awake or static body's 0. */
static double sleep_guess(const body_store *s, int i, double threshold)
{
    return (s->flags[i] & BODY_AWAKE) || s->type[i] == CAROM_BODY_STATIC ? 0.0 : threshold;
}

static unsigned body_bits(const body_store *s, int i, xform x, aabb fat, int moved, double threshold)
{
    xform guess = collided_guess(s, i, x);
    int same_fat = same_bits(&fat, &s->fat_box[i], sizeof fat);
    int same_previous = same_bits(&x.p, &s->previous_origin[i], sizeof x.p) && same_bits(&x.q, &s->previous_rotation[i], sizeof x.q);
    return ((s->flags[i] & BODY_AWAKE) ? REC_AWAKE : 0) | ((s->flags[i] & BODY_HAS_FORCE) ? REC_FORCE_FLAG : 0) |
           (moved ? REC_MOVED : 0) | (v3_is_zero(s->velocity[i]) ? 0 : REC_VELOCITY) |
           (v3_is_zero(s->angular_velocity[i]) ? 0 : REC_SPIN) | (v3_is_zero(s->force[i]) ? 0 : REC_FORCE) |
           (f64_bits(s->sleep_time[i]) == f64_bits(sleep_guess(s, i, threshold)) ? 0 : REC_SLEEP_TIME) | (same_previous ? 0 : REC_PREVIOUS) |
           (same_fat ? 0 : REC_FAT) | (v3_is_zero(s->torque[i]) ? 0 : REC_TORQUE) |
           (same_bits(&s->collided[i], &(xform){guess.p, guess.q}, sizeof(xform)) ? 0 : REC_COLLIDED);
}

/* (counting: snapshot_field_bytes's pass, which keeps bytes per field; the
 * other pass has none of its arithmetic: write_bodies) */
SNAP_INLINE void write_bodies_pass(writer *o, const carom_world *w, const class_table *t, const xform *pose, const int counting)
{
    const body_store *s = &w->bodies;
    size_t at = o->pos;
    put_varint(o, (uint64_t)t->count);
    put_bytes(o, t->bytes, t->size);
    put_varint(o, (uint64_t)s->count);
    if (counting) acct(o, SNAP_FIELD_classes, at);
    vec3 last_center = v3(0, 0, 0);
    quat last_rotation = {1, 0, 0, 0};
    double last_sleep = 0;
    unsigned char scratch[SNAP_RECORD_MAX], *buf = o->buf;
    size_t pos = o->pos, cap = o->cap, direct = record_room(o);
    for (int i = 0; i < s->count; i++) {
        xform x = pose[i];
        aabb fat = predicted_fat_box(w, i);
        unsigned bits = body_bits(s, i, x, fat, bp_is_moved(w->bp, s->proxy[i]), w->def.sleep_time);
        unsigned char *const record = record_begin(buf, pos, direct, scratch);
        unsigned char *wp = record, *at = wp;
        wp = cur_varint(wp, bits);
        wp = cur_varint(wp, (uint64_t)t->of_body[i]);
        if (counting) o->acct[SNAP_FIELD_body_header] += (size_t)(wp - at);
        at = wp;
        wp = cur_coded_v3(wp, s->center[i], last_center);
        if (counting) o->acct[SNAP_FIELD_body_center] += (size_t)(wp - at);
        at = wp;
        wp = cur_coded_q(wp, s->rotation[i], last_rotation);
        if (counting) o->acct[SNAP_FIELD_body_orientation] += (size_t)(wp - at);
        last_center = s->center[i];
        last_rotation = s->rotation[i];
        at = wp;
        if (bits & REC_VELOCITY) wp = cur_coded_v3(wp, s->velocity[i], v3(0, 0, 0));
        if (counting) o->acct[SNAP_FIELD_body_velocity] += (size_t)(wp - at);
        at = wp;
        if (bits & REC_SPIN) wp = cur_coded_v3(wp, s->angular_velocity[i], v3(0, 0, 0));
        if (counting) o->acct[SNAP_FIELD_body_spin] += (size_t)(wp - at);
        at = wp;
        if (bits & REC_FORCE) wp = cur_coded_v3(wp, s->force[i], v3(0, 0, 0));
        if (bits & REC_TORQUE) wp = cur_coded_v3(wp, s->torque[i], v3(0, 0, 0));
        if (counting) o->acct[SNAP_FIELD_body_force] += (size_t)(wp - at);
        at = wp;
        if (bits & REC_SLEEP_TIME) { wp = cur_coded1(wp, s->sleep_time[i], last_sleep); last_sleep = s->sleep_time[i]; }
        if (counting) o->acct[SNAP_FIELD_body_sleep] += (size_t)(wp - at);
        at = wp;
        if (s->flags[i] & BODY_LOCK_PLANE) wp = cur_coded1(wp, s->plane_offset[i], v3_dot(s->plane_normal[i], s->center[i]));
        if (counting) o->acct[SNAP_FIELD_body_plane] += (size_t)(wp - at);
        at = wp;
        if (bits & REC_PREVIOUS) {
            wp = cur_coded_v3(wp, s->previous_origin[i], x.p);
            wp = cur_coded_q(wp, s->previous_rotation[i], x.q);
        }
        if (counting) o->acct[SNAP_FIELD_body_previous] += (size_t)(wp - at);
        at = wp;
        if (bits & REC_COLLIDED) {
            xform p = collided_guess(s, i, x);
            wp = cur_coded_v3(wp, s->collided[i].p, p.p);
            wp = cur_coded_q(wp, s->collided[i].q, p.q);
        }
        if (counting) o->acct[SNAP_FIELD_body_collided] += (size_t)(wp - at);
        at = wp;
        if (bits & REC_FAT) { wp = cur_coded_v3(wp, s->fat_box[i].lo, fat.lo); wp = cur_coded_v3(wp, s->fat_box[i].hi, fat.hi); }
        if (counting) o->acct[SNAP_FIELD_body_fat] += (size_t)(wp - at);
        pos = record_end(buf, pos, cap, record, wp, scratch);
    }
    o->pos = pos;
}

static void write_bodies(writer *o, const carom_world *w, const class_table *t, const xform *pose)
{
    if (o->acct) write_bodies_pass(o, w, t, pose, 1);
    else write_bodies_pass(o, w, t, pose, 0);
}

static const xform identity_pose = {{0, 0, 0}, {1, 0, 0, 0}};

/* B's frame in A's (as collision.c computes it). */
static xform relative_pose(xform xa, xform xb)
{
    xform r = {xf_inv_point(xa, xb.p), q_mul(q_conj(xa.q), xb.q)};
    return r;
}

/* What a reusable manifold's points and separations become when the
 * collision stage keeps it (collision.c, reuse_manifold): B's motion in A's
 * frame since rel_pose, x -> R x + t, at the poses the last test used. The
 * snapshot predicts a point's world position and separation from it. */
typedef struct reuse_motion {
    int on;
    mat3 R;
    vec3 t;
} reuse_motion;

static void reuse_guess(const contact *c, const xform *now, reuse_motion *m)
{
    m->on = 0; /* (R and t are read only when on) */
    if (!(c->flags & CONTACT_REUSABLE)) return;
    quat dq = q_mul(now->q, q_conj(c->rel_pose.q));
    m->on = 1;
    m->R = m3_from_quat(dq);
    m->t = v3_sub(now->p, q_rotate(dq, c->rel_pose.p));
}

/* A point's predicted world position and separation now, from its state. */
static void point_guess(const reuse_motion *m, const contact_data *d, xform xa, const contact_point_state *st, vec3 *point,
                        double *separation)
{
    if (!m->on) {
        *point = xf_point(xa, st->local_a);
        *separation = st->separation;
        return;
    }
    vec3 moved = v3_sub(v3_add(m3_mulv(m->R, st->local_a), m->t), st->local_a);
    *separation = st->separation + v3_dot(d->normal_a, moved);
    *point = xf_point(xa, v3_madd(st->local_a, 0.5, moved));
}

/* contact record bits, after the point count (3 bits); a contact's head
 * varint is its flags (6 bits) | bits << 6, so a touching manifold's usual
 * record (count, feature, exact points, cache normal, basis as predicted,
 * flip) fits its first 14 bits: two bytes. CREC_B_FIRST (format 7 only):
 * the pair's body A (the solve's first, collision.c) is the higher id of
 * the two written, without it the lower; format 8 writes A's id first and
 * has no such bit (it cost a settled pile's idle pairs 3 bytes each: their
 * head grew from one byte to four). */
enum { CREC_FEATURE = 8, CREC_EXACT = 16, CREC_HAS_NORMAL = 32, CREC_TANGENT_GUESS = 64, CREC_FLIP = 128,
       CREC_NORMAL = 256, CREC_SUB = 512, CREC_SUB_LIMIT = 1024, CREC_TANGENT = 2048, CREC_CACHE_NORMAL = 4096,
       CREC_MATERIAL = 8192, CREC_POSE = 16384, CREC_REACH = 32768, CREC_NORMAL_A = 65536, CREC_ALL = 131071,
       CREC_B_FIRST = 131072, CREC_ALL_7 = 262143 };
#define CONTACT_FLAG_BITS 6
/* The flags under which a pair's record has more than its ids, head and
 * cache feature (its data is read, or it is posed) */
#define IDLE_RECORD_FLAGS (CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_ANY_TOUCHING | CONTACT_REUSABLE | CONTACT_APART)

/* The friction basis the solver starts from for a normal (solver.c): the
 * kept basis of a resting contact is usually this, to the last bits. */
static vec3 basis_guess(vec3 n) { return contact_rest_basis(n); }

/* A manifold normal is read while the pair touches, or touched last step (its
 * end event); otherwise the next collision test rewrites it before anything
 * reads it (collision.c), so it is not state and is not written. */
static int normal_is_state(const contact *c, const contact_data *d)
{
    return d->m.count > 0 || (c->flags & (CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_ANY_TOUCHING));
}

/* What the reader predicts from the two bodies, before the contact's numbers:
 * their collided poses, and the material only for a pair with data (a pair
 * without reads the bodies' mix: nothing to predict). */
typedef struct contact_guess {
    const xform *xa, *xb;
    double material[3]; /* friction, restitution, rolling resistance as material.c mixes them */
    int have_basis;     /* basis: the friction basis predicted from the cache normal, once made */
    vec3 basis;
} contact_guess;

/* (a square root and a division: made once a contact, where a basis is kept) */
static vec3 guess_basis(contact_guess *g, const contact *c)
{
    if (!g->have_basis) {
        g->basis = basis_guess(c->cache.normal);
        g->have_basis = 1;
    }
    return g->basis;
}

/* material_mix depends on the two bodies' classes alone for a pair's first
 * manifold (sub 0): mixed once per pair of classes (the same bits). */
#define MIX_MEMO_CLASSES 32
typedef struct mix_memo {
    const int *class_of;    /* per slot */
    double mix[MIX_MEMO_CLASSES * MIX_MEMO_CLASSES][3];
    unsigned char have[MIX_MEMO_CLASSES * MIX_MEMO_CLASSES];
    double reach[MIX_MEMO_CLASSES]; /* shape_bounding_radius of each class's shape */
    unsigned char have_reach[MIX_MEMO_CLASSES];
} mix_memo;

static void mix_memo_init(mix_memo *m, const int *class_of)
{
    m->class_of = class_of;
    memset(m->have, 0, sizeof m->have);
    memset(m->have_reach, 0, sizeof m->have_reach);
}

/* A body's bounding radius (its class's shape's: the same bits). */
static double body_reach(const body_store *s, mix_memo *memo, int slot)
{
    int k = memo ? memo->class_of[slot] : MIX_MEMO_CLASSES;
    if (k >= MIX_MEMO_CLASSES) return shape_bounding_radius(&s->shapes[slot]);
    if (!memo->have_reach[k]) {
        memo->reach[k] = shape_bounding_radius(&s->shapes[slot]);
        memo->have_reach[k] = 1;
    }
    return memo->reach[k];
}

static void guess_material(const body_store *s, mix_memo *memo, int a, int b, uint32_t sub, contact_guess *g)
{
    int ka = memo ? memo->class_of[a] : MIX_MEMO_CLASSES, kb = memo ? memo->class_of[b] : MIX_MEMO_CLASSES;
    if (sub == 0 && ka < MIX_MEMO_CLASSES && kb < MIX_MEMO_CLASSES) {
        int k = ka * MIX_MEMO_CLASSES + kb;
        if (!memo->have[k]) {
            material_mix(s, a, b, 0, memo->mix[k]);
            memo->have[k] = 1;
        }
        memcpy(g->material, memo->mix[k], sizeof g->material);
    } else {
        material_mix(s, a, b, sub, g->material);
    }
}

/* A contact's record bits, from its state and the reader's predictions. */
SNAP_INLINE unsigned contact_bits(const contact *c, const contact_data *d, contact_guess *gp, const vec3 *normal,
                                  const vec3 *cache_guess, const xform *rel, double reach, const vec3 *normal_a)
{
    const double *mix = gp->material;
    int posed = (c->flags & (CONTACT_REUSABLE | CONTACT_APART)) != 0;
    int tangent_guessed = 0;
    if (!v3_is_zero(d->tangent1)) { /* (the prediction's square root only where a basis is kept) */
        vec3 basis = guess_basis(gp, c);
        tangent_guessed = same_bits(&d->tangent1, &basis, sizeof basis);
    }
    return (unsigned)d->m.count | (c->cache.has_normal ? CREC_HAS_NORMAL : 0) | (c->cache.flip ? CREC_FLIP : 0) |
                        (c->sub ? CREC_SUB : 0) | (c->sub_limit ? CREC_SUB_LIMIT : 0) | (c->cache.feature != -1 ? CREC_FEATURE : 0) |
                        (v3_is_zero(d->tangent1) ? 0 : tangent_guessed ? CREC_TANGENT_GUESS : CREC_TANGENT) |
                        (v3_is_zero(*normal) || d->m.count > 0 ? 0 : CREC_NORMAL) | /* (a manifold with points: always written) */
                        (same_bits(&c->cache.normal, cache_guess, sizeof *cache_guess) ? 0 : CREC_CACHE_NORMAL) |
                        (!c->slot || (f64_bits(d->friction) == f64_bits(mix[0]) && f64_bits(d->restitution) == f64_bits(mix[1]) &&
                                    f64_bits(d->rolling_resistance) == f64_bits(mix[2]))
                             ? 0 : CREC_MATERIAL) | /* (a pair without data has the bodies' mix) */
                        (posed && !(same_bits(&c->rel_pose.p, &rel->p, sizeof rel->p) && same_bits(&c->rel_pose.q, &rel->q, sizeof rel->q))
                             ? CREC_POSE : 0) |
                        ((c->flags & CONTACT_APART) && f64_bits(c->reach_b) != f64_bits(reach) ? CREC_REACH : 0) |
                        ((c->flags & CONTACT_REUSABLE) && !same_bits(&d->normal_a, normal_a, sizeof *normal_a) ? CREC_NORMAL_A : 0);
}

/* A contact's two bodies: zvar A's id less the previous contact's A, then
 * var zigzag(B's id - A's id) - 1 (B is never A). */
SNAP_INLINE unsigned char *cur_pair(unsigned char *wp, const contact *c, int *last_a)
{
    wp = cur_varint(wp, zigzag((int64_t)c->id_a - *last_a));
    wp = cur_varint(wp, zigzag((int64_t)c->id_b - c->id_a) - 1);
    *last_a = c->id_a;
    return wp;
}

SNAP_INLINE void write_contacts_pass(writer *o, const carom_world *w, const class_table *t, const int counting)
{
    const body_store *s = &w->bodies;
    const contact_set *cs = &w->contacts;
    mix_memo *memo = malloc(sizeof *memo); /* (without it, every contact mixes its own) */
    if (memo) mix_memo_init(memo, t->of_body);
    size_t count_at = o->pos;
    put_varint(o, (uint64_t)cs->count);
    if (counting) acct(o, SNAP_FIELD_contact_header, count_at);
    int last_a = 0;
    unsigned char scratch[SNAP_RECORD_MAX], *buf = o->buf;
    size_t pos = o->pos, cap = o->cap, direct = record_room(o);
    for (int i = 0; i < cs->count; i++) {
        const contact *c = &cs->items[i];
        /* the pair as body A, then B (the cache holds new pairs in rank
         * order, so A's ids follow one another closely: 2.5 % fewer id
         * bytes on a settled pile than the lower id first) */
        const contact_data *d = CONTACT_DATA(cs, i);
        if (!c->slot && !(c->flags & IDLE_RECORD_FLAGS) && !c->sub && !c->sub_limit && v3_is_zero(c->cache.normal)) {
            /* a broadphase pair without data (most of a settled pile's):
             * what the general path below writes for it, without its
             * predictions (slot 0 reads the empty record: no points, normal,
             * basis or material; not posed) */
            unsigned char *const record = record_begin(buf, pos, direct, scratch);
            unsigned char *wp = record, *at = wp;
            unsigned bits = (c->cache.has_normal ? CREC_HAS_NORMAL : 0) | (c->cache.flip ? CREC_FLIP : 0) |
                            (c->cache.feature != -1 ? CREC_FEATURE : 0);
            wp = cur_pair(wp, c, &last_a);
            wp = cur_varint(wp, (uint64_t)c->flags | (uint64_t)bits << CONTACT_FLAG_BITS);
            if (bits & CREC_FEATURE) wp = cur_varint(wp, zigzag(c->cache.feature));
            if (counting) o->acct[SNAP_FIELD_contact_header] += (size_t)(wp - at);
            pos = record_end(buf, pos, cap, record, wp, scratch);
            continue;
        }
        int a = s->ids[c->id_a].slot, b = s->ids[c->id_b].slot;
        contact_guess g = {&s->collided[a], &s->collided[b], {0, 0, 0}, 0, {0, 0, 0}};
        if (c->slot) guess_material(s, memo, a, b, c->sub, &g);
        /* what the reader will hold, and predict from */
        vec3 normal = normal_is_state(c, d) ? d->m.normal : v3(0, 0, 0);
        vec3 cache_guess = c->cache.has_normal ? normal : v3(0, 0, 0);
        int posed = (c->flags & (CONTACT_REUSABLE | CONTACT_APART)) != 0;
        xform rel = posed ? relative_pose(*g.xa, *g.xb) : identity_pose;
        double reach = (c->flags & CONTACT_APART) ? body_reach(s, memo, b) : 0.0;
        vec3 normal_a = (c->flags & CONTACT_REUSABLE) ? q_inv_rotate(g.xa->q, normal) : normal;
        unsigned bits = contact_bits(c, d, &g, &normal, &cache_guess, &rel, reach, &normal_a);
        /* every point where the reader predicts it (a settled pile's kept
         * manifolds): their positions and separations are not written */
        reuse_motion m;
        reuse_guess(c, &rel, &m); /* (rel: B's collided pose in A's when posed) */
        int exact = d->m.count > 0;
        vec3 guess_point[MANIFOLD_MAX_POINTS];
        double guess_separation[MANIFOLD_MAX_POINTS];
        for (int k = 0; k < d->m.count; k++) {
            point_guess(&m, d, *g.xa, &d->state[k], &guess_point[k], &guess_separation[k]);
            exact = exact && same_bits(&guess_point[k], &d->m.points[k].point, sizeof(vec3)) &&
                    f64_bits(guess_separation[k]) == f64_bits(d->m.points[k].separation);
        }
        if (exact) bits |= CREC_EXACT;
        unsigned char *const record = record_begin(buf, pos, direct, scratch);
        unsigned char *wp = record, *at = wp;
        wp = cur_pair(wp, c, &last_a);
        wp = cur_varint(wp, (uint64_t)c->flags | (uint64_t)bits << CONTACT_FLAG_BITS);
        if (bits & CREC_SUB) wp = cur_varint(wp, c->sub);
        if (bits & CREC_SUB_LIMIT) wp = cur_varint(wp, c->sub_limit);
        if (bits & CREC_FEATURE) wp = cur_varint(wp, zigzag(c->cache.feature));
        if (counting) o->acct[SNAP_FIELD_contact_header] += (size_t)(wp - at);
        at = wp;
        if (d->m.count > 0 || (bits & CREC_NORMAL)) wp = cur_coded_v3(wp, normal, v3(0, 0, 0));
        if (counting) o->acct[SNAP_FIELD_contact_normal] += (size_t)(wp - at);
        at = wp;
        if (bits & CREC_CACHE_NORMAL) wp = cur_coded_v3(wp, c->cache.normal, cache_guess);
        if (counting) o->acct[SNAP_FIELD_contact_cache_normal] += (size_t)(wp - at);
        at = wp;
        if (bits & CREC_MATERIAL) {
            double v[3] = {d->friction, d->restitution, d->rolling_resistance};
            wp = cur_coded(wp, v, g.material, 3);
        }
        if (counting) o->acct[SNAP_FIELD_contact_material] += (size_t)(wp - at);
        at = wp;
        if (bits & CREC_TANGENT) wp = cur_coded_v3(wp, d->tangent1, guess_basis(&g, c));
        if (counting) o->acct[SNAP_FIELD_contact_basis] += (size_t)(wp - at);
        /* only what the collision stage reads under each flag (collision.c):
         * the pose and gap of a pair known apart, the pose and normal of a
         * manifold it may reuse */
        if (bits & CREC_POSE) {
            at = wp;
            wp = cur_coded_v3(wp, c->rel_pose.p, rel.p);
            if (counting) o->acct[SNAP_FIELD_contact_rel_position] += (size_t)(wp - at);
            at = wp;
            wp = cur_coded_q(wp, c->rel_pose.q, rel.q);
            if (counting) o->acct[SNAP_FIELD_contact_rel_rotation] += (size_t)(wp - at);
        }
        at = wp;
        if (c->flags & CONTACT_APART) wp = cur_coded1(wp, c->gap, 0.0);
        if (counting) o->acct[SNAP_FIELD_contact_gap] += (size_t)(wp - at);
        at = wp;
        if (bits & CREC_REACH) wp = cur_coded1(wp, c->reach_b, reach);
        if (counting) o->acct[SNAP_FIELD_contact_reach] += (size_t)(wp - at);
        at = wp;
        if (bits & CREC_NORMAL_A) wp = cur_coded_v3(wp, d->normal_a, normal_a);
        if (counting) o->acct[SNAP_FIELD_contact_normal_a] += (size_t)(wp - at);
        /* each point against the one before it (a manifold's points share
         * their scale, most bits of their impulses, often all but a sign) */
        double last[7] = {0, 0, 0, 0, 0, 0, 0};
        for (int k = 0; k < d->m.count; k++) {
            const manifold_point *p = &d->m.points[k];
            const contact_point_state *st = &d->state[k];
            double cur[7] = {st->local_a.x, st->local_a.y, st->local_a.z, st->separation,
                             st->normal_impulse, st->tangent_impulse[0], st->tangent_impulse[1]};
            at = wp;
            wp = cur_varint(wp, p->id ^ (k ? d->m.points[k - 1].id : 0)); /* (a manifold's ids share their high bits) */
            if (counting) o->acct[SNAP_FIELD_point_id] += (size_t)(wp - at);
            at = wp;
            wp = cur_coded(wp, cur, last, 3);
            if (counting) o->acct[SNAP_FIELD_point_local] += (size_t)(wp - at);
            at = wp;
            wp = cur_coded(wp, cur + 3, last + 3, 4);
            if (counting && o->acct) { /* the group's bytes by value: half a tag byte each, and its payload */
                static const int field[4] = {SNAP_FIELD_point_separation, SNAP_FIELD_point_normal_impulse,
                                             SNAP_FIELD_point_tangent_impulse, SNAP_FIELD_point_tangent_impulse};
                for (int v = 0; v < 4; v++) {
                    int tg = coded_tag(f64_bits(cur[3 + v]) ^ f64_bits(last[3 + v]));
                    o->acct[field[v]] += (size_t)(tg <= 8 ? tg : 16 - tg) + (v % 2 == 0 ? 1 : 0);
                }
            }
            if (!exact) {
                unsigned char *pw = wp;
                wp = cur_coded_v3(wp, p->point, guess_point[k]);
                wp = cur_coded1(wp, p->separation, guess_separation[k]);
                if (counting) o->acct[SNAP_FIELD_point_world] += (size_t)(wp - pw);
            }
            memcpy(last, cur, sizeof cur);
        }
        pos = record_end(buf, pos, cap, record, wp, scratch);
    }
    o->pos = pos;
    free(memo);
}

static void write_contacts(writer *o, const carom_world *w, const class_table *t)
{
    if (o->acct) write_contacts_pass(o, w, t, 1);
    else write_contacts_pass(o, w, t, 0);
}

static void write_world(writer *o, const carom_world *w, const class_table *t, const xform *pose)
{
    const body_store *s = &w->bodies;
    size_t at = o->pos;
    write_def(o, &w->def);
    put_f64(o, 0.0); /* reserved: was the last step's dt (each step now carries its own) */
    put_u64(o, (uint64_t)w->stats.step_count);
    acct(o, SNAP_FIELD_settings, at);
    at = o->pos;
    put_varint(o, (uint64_t)s->id_count);
    put_varint(o, (uint64_t)(s->free_id + 1));
    for (int i = 0; i < s->id_count; i++) {
        put_varint(o, zigzag((int64_t)s->ids[i].slot - i));
        put_varint(o, s->ids[i].generation);
        put_varint(o, (uint64_t)(s->ids[i].next_free + 1));
    }
    acct(o, SNAP_FIELD_ids, at);
    write_bodies(o, w, t, pose);
    write_contacts(o, w, t);
    /* the sensors' overlaps after the last step (sensor.c): their next events */
    at = o->pos;
    put_varint(o, (uint64_t)w->sensor_overlap_count);
    for (int i = 0; i < w->sensor_overlap_count; i++) {
        put_u64(o, carom_body_id_pack(w->sensor_overlaps[i].sensor));
        put_u64(o, carom_body_id_pack(w->sensor_overlaps[i].other));
    }
    acct(o, SNAP_FIELD_sensors, at);
}

static size_t snapshot_to(const carom_world *w, void *buf, size_t capacity, size_t *bytes);

CAROM_API size_t carom_world_snapshot(const carom_world *w, void *buf, size_t capacity)
{
    if (!w) return 0;
    return snapshot_to(w, buf, capacity, NULL);
}

size_t snapshot_field_bytes(const carom_world *w, size_t bytes[SNAP_FIELD_COUNT], const char *names[SNAP_FIELD_COUNT])
{
#define SNAP_FIELD_NAME(f) #f,
    static const char *const field_names[SNAP_FIELD_COUNT] = {SNAP_FIELDS(SNAP_FIELD_NAME)};
#undef SNAP_FIELD_NAME
    for (int f = 0; f < SNAP_FIELD_COUNT; f++) {
        bytes[f] = 0;
        names[f] = field_names[f];
    }
    return snapshot_to(w, NULL, 0, bytes);
}

static size_t snapshot_to(const carom_world *w, void *buf, size_t capacity, size_t *bytes)
{
    if (w->locked) {
        world_fail(w, CAROM_ERROR_LOCKED, "world_snapshot: the world is inside its step; snapshot it afterwards");
        return 0;
    }
    class_table t;
    int n = w->bodies.count;
    xform *pose = malloc(sizeof *pose * (size_t)(n > 0 ? n : 1));
    if (!pose || !build_classes(&w->bodies, &t)) {
        free(pose);
        world_fail(w, CAROM_ERROR_OUT_OF_MEMORY, "world_snapshot: out of memory");
        return 0;
    }
    for (int i = 0; i < n; i++) pose[i] = body_xform(&w->bodies, i);
    if (!buf) capacity = 0;
    writer o = {buf, capacity, 0, bytes};
    put_bytes(&o, SNAP_MAGIC, 8);
    put_u32(&o, SNAP_VERSION);
    put_u32(&o, SNAP_HEADER_SIZE);
    put_u64(&o, 0); /* total size, filled below */
    put_u64(&o, 0); /* checksum, filled below */
    acct(&o, SNAP_FIELD_header, 0);
    write_world(&o, w, &t, pose);
    class_table_free(&t);
    free(pose);
    if (o.pos <= capacity) {
        writer h = {buf, capacity, 16, NULL};
        put_u64(&h, (uint64_t)o.pos);
        put_u64(&h, checksum((const unsigned char *)buf + SNAP_HEADER_SIZE, o.pos - SNAP_HEADER_SIZE));
    }
    return o.pos;
}

/* ---- reading it back ------------------------------------------------------------------ */

typedef struct body_class {
    int type;
    uint32_t flags;
    vec3 local_center, plane_normal;
    double mass, friction, restitution, linear_damping, angular_damping, gravity_scale;
    mat3 inertia, inv_inertia; /* (the inverse once per class: each body's is the same bits) */
    uint64_t category, mask;
    int group, combine;
    double force_threshold, rolling_resistance;
    size_t shape_at;        /* where its shape starts in the snapshot */
    size_t start, end;      /* its bytes */
    shape shape;            /* read once; bodies of a primitive or hull class copy it */
} body_class;

/* One class, checked as the API checks a body def; its shape is read (and
 * checked) here and again, from shape_at, for every body of the class. */
static int read_class(reader *r, body_class *k)
{
    k->start = r->pos;
    k->type = (int)get_u8(r, "class type");
    k->flags = get_u32(r, "class flags");
    k->local_center = get_v3(r, "class centre of mass");
    k->mass = get_f64(r, "class mass");
    k->inertia = get_m3(r, "class inertia");
    k->friction = get_f64(r, "class friction");
    k->restitution = get_f64(r, "class restitution");
    k->linear_damping = get_f64(r, "class damping");
    k->angular_damping = get_f64(r, "class damping");
    k->gravity_scale = get_f64(r, "class gravity scale");
    k->plane_normal = get_v3(r, "class plane normal");
    k->category = get_u64(r, "class filter");
    k->mask = get_u64(r, "class filter");
    k->group = get_i32(r, "class filter");
    k->force_threshold = get_f64(r, "class force threshold");
    k->rolling_resistance = get_f64(r, "class rolling resistance");
    k->combine = (int)get_u8(r, "class combine mode");
    if (r->failed) return 0;
    if (!(k->force_threshold >= 0 && k->rolling_resistance >= 0 && k->rolling_resistance <= RANGE_FRICTION_MAX &&
          k->combine <= CAROM_COMBINE_MAX))
        return bad(r, "a body class's force threshold, rolling resistance or combine mode is out of range");
    int type = k->type;
    if (type != CAROM_BODY_STATIC && type != CAROM_BODY_KINEMATIC && type != CAROM_BODY_DYNAMIC)
        return bad(r, "a body class has type %d", type);
    if (k->flags & ~(uint32_t)(BODY_KNOWN_FLAGS & ~BODY_STATE_FLAGS)) return bad(r, "a body class has unknown flags");
    if (!(fabs(k->local_center.x) <= RANGE_LENGTH_MAX && fabs(k->local_center.y) <= RANGE_LENGTH_MAX &&
          fabs(k->local_center.z) <= RANGE_LENGTH_MAX))
        return bad(r, "a body class's centre of mass is beyond 1e6 m");
    if (type == CAROM_BODY_DYNAMIC) {
        mat3 I = k->inertia;
        double trace = I.c0.x + I.c1.y + I.c2.z;
        if (!(k->mass >= RANGE_MASS_MIN && k->mass <= RANGE_MASS_MAX))
            return bad(r, "a body class's mass %g is outside [1e-9, 1e15] kg", k->mass);
        if (!(trace <= RANGE_INERTIA_MAX && m3_det(I) / (trace * trace) >= RANGE_INERTIA_MIN))
            return bad(r, "a body class's inertia is outside [1e-24, 1e30] kg m^2");
        if (!(trace * trace * trace / m3_det(I) <= RANGE_ANISOTROPY_MAX))
            return bad(r, "a body class's inertia anisotropy trace^3/det is above 1e12");
        /* an inertia tensor is symmetric with diagonal terms >= 0 and none
         * above the trace (a fuzzed one with a term of -5e84 passed the two
         * checks above and sent bodies to inf) */
        double e[3][3] = {{I.c0.x, I.c0.y, I.c0.z}, {I.c1.x, I.c1.y, I.c1.z}, {I.c2.x, I.c2.y, I.c2.z}};
        for (int u = 0; u < 3; u++)
            for (int v = 0; v < 3; v++)
                if (!(fabs(e[u][v]) <= trace && fabs(e[u][v] - e[v][u]) <= 1e-9 * trace && (u != v || e[u][v] >= 0)))
                    return bad(r, "a body class's inertia is not a symmetric tensor");
    }
    if (!(k->mass >= 0) ||
        !(k->friction >= 0 && k->friction <= RANGE_FRICTION_MAX && k->restitution >= 0 && k->restitution <= 1 &&
          k->linear_damping >= 0 && k->linear_damping <= RANGE_DAMPING_MAX && k->angular_damping >= 0 &&
          k->angular_damping <= RANGE_DAMPING_MAX && fabs(k->gravity_scale) <= RANGE_GRAVITY_SCALE_MAX))
        return bad(r, "a body class's mass, material, damping or gravity scale is out of range");
    if ((k->flags & BODY_LOCK_PLANE) && fabs(v3_len(k->plane_normal) - 1.0) > 1e-9)
        return bad(r, "a body class's plane normal is not unit");
    k->inv_inertia = k->type == CAROM_BODY_DYNAMIC ? m3_inverse(k->inertia) : m3_zero();
    k->shape_at = r->pos;
    shape sh;
    int ok = read_shape(r, &sh, type, 0);
    if (ok) k->shape = sh;
    else shape_free_data(&sh);
    k->end = r->pos;
    return ok;
}

/* The id table, read into the store of a world just created from the def. */
static int read_ids(reader *r, body_store *s)
{
    int id_count = get_small(r, 0, 1 << 26, 0, "id count");
    int free_id = get_small(r, 0, id_count, 0, "free id") - 1;
    if (r->failed) return 0;
    if ((size_t)id_count * 3 > r->size - r->pos) return bad(r, "truncated: %d ids need more than the bytes left", id_count);
    body_id_entry *ids = s->ids;
    if (!ids || s->id_capacity < id_count) {
        ids = malloc(sizeof *ids * (size_t)(id_count > 0 ? id_count : 1));
        if (!ids) return no_memory(r);
        free(s->ids);
        s->ids = ids;
        s->id_capacity = id_count > 0 ? id_count : 1;
    }
    s->id_count = 0;
    s->free_id = -1;
    for (int i = 0; i < id_count && !r->failed; i++) {
        ids[i].slot = i + get_small(r, -1 - (int64_t)i, (int64_t)id_count - i, 1, "id slot");
        ids[i].generation = (uint32_t)get_small(r, 0, UINT32_MAX, 0, "id generation");
        ids[i].next_free = get_small(r, 0, id_count, 0, "id free link") - 1;
    }
    if (r->failed) return 0;
    s->id_count = id_count;
    s->free_id = free_id;
    return 1;
}

/* Every live id names a distinct slot below count; the free list visits every free id once. */
static int check_ids(reader *r, body_store *s, int count)
{
    const body_id_entry *ids = s->ids;
    int live = 0, free_ids = 0;
    for (int i = 0; i < s->id_count; i++) {
        if (ids[i].slot < -1 || ids[i].slot >= count) return bad(r, "id %d has slot %d of %d", i, ids[i].slot, count);
        if (ids[i].slot >= 0) live++;
        else free_ids++;
    }
    if (live != count) return bad(r, "%d live ids for %d bodies", live, count);
    int walked = 0;
    for (int f = s->free_id; f >= 0; f = ids[f].next_free)
        if (ids[f].slot >= 0 || ++walked > free_ids) return bad(r, "the free id list is corrupt");
    if (walked != free_ids) return bad(r, "the free id list misses ids");
    for (int i = 0; i < count; i++) s->id_index[i] = -1;
    for (int i = 0; i < s->id_count; i++)
        if (ids[i].slot >= 0) {
            if (s->id_index[ids[i].slot] >= 0) return bad(r, "two ids share slot %d", ids[i].slot);
            s->id_index[ids[i].slot] = i;
        }
    return 1;
}

/* The writer merges equal classes: two equal ones are not its output. */
static int distinct_classes(reader *r, const body_class *k, int n)
{
    int cap = 16;
    while (cap < 2 * n) cap *= 2;
    int *slots = malloc(sizeof *slots * (size_t)cap);
    if (!slots) return no_memory(r);
    for (int i = 0; i < cap; i++) slots[i] = -1;
    for (int c = 0; c < n; c++) {
        size_t len = k[c].end - k[c].start;
        int h = (int)(hash_bytes(r->buf + k[c].start, len) & (uint64_t)(cap - 1));
        for (; slots[h] >= 0; h = (h + 1) & (cap - 1)) {
            const body_class *o = &k[slots[h]];
            if (o->end - o->start == len && memcmp(r->buf + o->start, r->buf + k[c].start, len) == 0) {
                int same = slots[h];
                free(slots);
                return bad(r, "body classes %d and %d are the same", same, c);
            }
        }
        slots[h] = c;
    }
    free(slots);
    return 1;
}

/* "body <i>" (what its errors say) from "body <i - 1>", in place: the
 * last digit counted up, a carry into the ones before it, a new leading 1
 * after a run of nines (the decimal digits made afresh for every body cost
 * 90 instructions a body) */
static void body_label_next(char what[48])
{
    size_t n = strlen(what);
    size_t k = n;
    while (k > 5 && what[k - 1] == '9') what[--k] = '0';
    if (k > 5) {
        what[k - 1]++;
        return;
    }
    memmove(what + 6, what + 5, n - 4); /* (the terminator too) */
    what[5] = '1';
}

static void free_classes(body_class *classes, int n)
{
    for (int k = 0; k < n; k++) shape_free_data(&classes[k].shape);
    free(classes);
}

/* A body's own copy of its class's shape: copied where the copy is the
 * shape the class read (a hull shared: hulls never change once built, and
 * a clone of each was 2,000 allocations, copies and frees a restore in the
 * bench's pile); meshes, height fields and compounds are read again from
 * the class's bytes. 0 on failure (reported). */
static int class_shape(reader *r, const body_class *k, shape *out)
{
    const shape *ks = &k->shape;
    switch (ks->type) {
    case SHAPE_SPHERE: case SHAPE_BOX: case SHAPE_CAPSULE: case SHAPE_CYLINDER: case SHAPE_PLANE:
        *out = *ks;
        return 1;
    case SHAPE_HULL:
        *out = *ks;
        out->hull = hull_share(ks->hull);
        return 1;
    default: {
        reader sr = *r;
        sr.pos = k->shape_at;
        if (read_shape(&sr, out, k->type, 0)) return 1;
        r->failed = 1;
        return 0;
    }
    }
}

/* class_of: each body's class (the caller frees it, whatever the result) */
static int read_bodies(reader *r, carom_world *w, int **class_of)
{
    body_store *s = &w->bodies;
    if (!read_ids(r, s)) return 0;
    int class_count = get_small(r, 0, 1 << 26, 0, "class count");
    if (r->failed) return 0;
    if ((size_t)class_count * 200 > r->size - r->pos) return bad(r, "truncated: %d body classes", class_count);
    body_class *classes = calloc((size_t)(class_count > 0 ? class_count : 1), sizeof *classes);
    if (!classes) return no_memory(r);
    for (int k = 0; k < class_count; k++)
        if (!read_class(r, &classes[k])) { free_classes(classes, class_count); return 0; }
    if (!distinct_classes(r, classes, class_count)) { free_classes(classes, class_count); return 0; }
    int count = get_small(r, 0, s->id_count, 0, "body count");
    if (r->failed || (size_t)count * 6 > r->size - r->pos) { /* the shortest body record */
        free_classes(classes, class_count);
        return r->failed ? 0 : bad(r, "truncated: %d bodies need more than the bytes left", count);
    }
    /* the dense arrays, sized for the bodies (the id table is kept aside
     * meanwhile), unless they have the room (a spare's) */
    int ok = 1;
    if (s->capacity < count) {
        body_id_entry *ids = s->ids;
        int id_count = s->id_count, free_id = s->free_id, id_capacity = s->id_capacity;
        s->ids = NULL;
        body_store_free(s);
        ok = body_store_init(s, count);
        free(s->ids);
        s->ids = ids;
        s->id_capacity = id_capacity;
        s->id_count = id_count;
        s->free_id = free_id;
    }
    if (!ok) { free_classes(classes, class_count); return no_memory(r); }
    if (!check_ids(r, s, count)) { free_classes(classes, class_count); return 0; }
    *class_of = malloc(sizeof **class_of * (size_t)(count > 0 ? count : 1));
    if (!*class_of) { free_classes(classes, class_count); return no_memory(r); }
    vec3 last_center = v3(0, 0, 0);
    quat last_rotation = {1, 0, 0, 0};
    double last_sleep = 0;
    int classes_used = 0;
    char what[48] = "body 0"; /* the record's name in messages */
    for (int i = 0; i < count; i++) {
        if (i > 0) body_label_next(what);
        int bits = get_small(r, 0, REC_ALL, 0, what);
        int ci = get_small(r, 0, class_count - 1, 0, what);
        if (r->failed) break;
        /* classes come in the order bodies first use them, each used */
        if (ci > classes_used) { bad(r, "body %d uses class %d before class %d", i, ci, classes_used); break; }
        if (ci == classes_used) classes_used++;
        (*class_of)[i] = ci;
        const body_class *k = &classes[ci];
        if (k->type == CAROM_BODY_STATIC && (bits & REC_AWAKE)) { bad(r, "static body %d is awake", i); break; }
        s->type[i] = k->type;
        s->flags[i] = k->flags | ((bits & REC_AWAKE) ? BODY_AWAKE : 0) | ((bits & REC_FORCE_FLAG) ? BODY_HAS_FORCE : 0);
        s->solver_index[i] = (bits & REC_MOVED) != 0; /* held here until the proxies exist */
        s->local_center[i] = k->local_center;
        s->mass[i] = k->mass;
        s->inertia_local[i] = k->inertia;
        s->friction[i] = k->friction;
        s->restitution[i] = k->restitution;
        s->linear_damping[i] = k->linear_damping;
        s->angular_damping[i] = k->angular_damping;
        s->gravity_scale[i] = k->gravity_scale;
        s->plane_normal[i] = k->plane_normal;
        s->category[i] = k->category;
        s->filter_mask[i] = k->mask;
        s->group[i] = k->group;
        s->force_threshold[i] = k->force_threshold;
        s->rolling_resistance[i] = k->rolling_resistance;
        s->combine[i] = k->combine;
        s->user_data[i] = NULL;
        s->proxy[i] = -1;
        s->center[i] = last_center = get_coded_v3(r, last_center, what);
        s->rotation[i] = last_rotation = get_coded_q(r, last_rotation, what);
        s->velocity[i] = (bits & REC_VELOCITY) ? get_coded_v3(r, v3(0, 0, 0), what) : v3(0, 0, 0);
        s->angular_velocity[i] = (bits & REC_SPIN) ? get_coded_v3(r, v3(0, 0, 0), what) : v3(0, 0, 0);
        s->force[i] = (bits & REC_FORCE) ? get_coded_v3(r, v3(0, 0, 0), what) : v3(0, 0, 0);
        s->torque[i] = (bits & REC_TORQUE) ? get_coded_v3(r, v3(0, 0, 0), what) : v3(0, 0, 0);
        s->sleep_time[i] = (bits & REC_SLEEP_TIME) ? (last_sleep = get_coded1(r, last_sleep, what)) : sleep_guess(s, i, w->def.sleep_time);
        s->plane_offset[i] = (k->flags & BODY_LOCK_PLANE) ? get_coded1(r, v3_dot(k->plane_normal, s->center[i]), what) : 0.0;
        if (r->failed) break;
        if (!within_cube(s->center[i], RANGE_STATE_COORDINATE_MAX)) { bad(r, "body %d is beyond 1e18 m", i); break; }
        quat q = s->rotation[i];
        if (not_unit(q)) { bad(r, "body %d orientation is not unit", i); break; }
        /* (a vector its bits say is absent is zero: no length to check) */
        if (((bits & REC_VELOCITY) && !(v3_len(s->velocity[i]) <= RANGE_SPEED_MAX)) ||
            ((bits & REC_SPIN) && !(v3_len(s->angular_velocity[i]) <= RANGE_SPEED_MAX))) {
            bad(r, "body %d moves faster than any world allows", i);
            break;
        }
        /* the force bound is the API's loosest (apply_force checks it against
         * the mass then; set_mass may lower the mass later) */
        if (((bits & REC_FORCE) && !(v3_len(s->force[i]) <= RANGE_ACCELERATION_MAX * RANGE_MASS_MAX)) || !(s->sleep_time[i] >= 0) ||
            ((bits & REC_TORQUE) && !(v3_len(s->torque[i]) <= RANGE_ACCELERATION_MAX * RANGE_INERTIA_MAX)) ||
            !(fabs(s->plane_offset[i]) <= RANGE_STATE_COORDINATE_MAX)) {
            bad(r, "body %d force, sleep timer or plane offset out of range", i);
            break;
        }
        /* the shape, from its class (each body owns its copy) */
        s->count = i; /* the shapes of bodies 0..i-1 are owned: freed if a later one fails */
        if (!class_shape(r, k, &s->shapes[i])) break;
        s->count = i + 1;
        xform x = body_xform(s, i);
        s->previous_origin[i] = (bits & REC_PREVIOUS) ? get_coded_v3(r, x.p, what) : x.p;
        s->previous_rotation[i] = (bits & REC_PREVIOUS) ? get_coded_q(r, x.q, what) : x.q;
        if (r->failed) break;
        if (!within_cube(s->previous_origin[i], RANGE_STATE_COORDINATE_MAX)) { bad(r, "body %d previous pose is beyond 1e18 m", i); break; }
        quat pq = s->previous_rotation[i];
        if ((bits & REC_PREVIOUS) && not_unit(pq)) { /* (else it is the orientation, checked above) */
            bad(r, "body %d previous orientation is not unit", i);
            break;
        }
        xform p = collided_guess(s, i, x);
        s->collided[i].p = (bits & REC_COLLIDED) ? get_coded_v3(r, p.p, what) : p.p;
        s->collided[i].q = (bits & REC_COLLIDED) ? get_coded_q(r, p.q, what) : p.q;
        if (r->failed) break;
        vec3 co = s->collided[i].p;
        quat cq = s->collided[i].q;
        if (!within_cube(co, RANGE_STATE_COORDINATE_MAX) ||
            ((bits & REC_COLLIDED) && not_unit(cq))) { /* (else a pose checked above) */
            bad(r, "body %d collided pose is beyond 1e18 m or not unit", i);
            break;
        }
        aabb predicted = predicted_fat_box(w, i), fat = predicted;
        if (bits & REC_FAT) {
            fat.lo = get_coded_v3(r, fat.lo, what);
            fat.hi = get_coded_v3(r, fat.hi, what);
        }
        s->fat_box[i] = fat;
        if (r->failed) break;
        if (!(fat.lo.x <= fat.hi.x && fat.lo.y <= fat.hi.y && fat.lo.z <= fat.hi.z)) { bad(r, "body %d bounds are inverted", i); break; }
        if (!(isfinite(fat.lo.x) && isfinite(fat.lo.y) && isfinite(fat.lo.z) && isfinite(fat.hi.x) && isfinite(fat.hi.y) &&
              isfinite(fat.hi.z))) { bad(r, "body %d bounds are not finite", i); break; }
        if (body_bits(s, i, x, predicted, s->solver_index[i], w->def.sleep_time) != (unsigned)bits) {
            bad(r, "body %d: its record bits do not match its fields (a field equal to its prediction written)", i);
            break;
        }
        /* derived fields, computed as body creation and the setters compute them */
        int dynamic = k->type == CAROM_BODY_DYNAMIC;
        s->inv_mass[i] = dynamic ? 1.0 / s->mass[i] : 0.0;
        s->inv_inertia_local[i] = k->inv_inertia;
        body_update_inertia(s, i);
    }
    free_classes(classes, class_count);
    if (!r->failed && classes_used != class_count) bad(r, "%d of %d body classes unused", class_count - classes_used, class_count);
    return !r->failed;
}

/* (sensor.c's pairs: a sensor id and another, two packed ids each) */
static int read_sensor_overlaps(reader *r, carom_world *w)
{
    int count = get_small(r, 0, 1 << 28, 0, "sensor overlap count");
    if (r->failed) return 0;
    if ((size_t)count * 16 > r->size - r->pos) return bad(r, "truncated: %d sensor overlaps", count);
    if (count == 0) return 1;
    sensor_overlap *pairs = malloc(sizeof *pairs * (size_t)count);
    if (!pairs) return no_memory(r);
    for (int i = 0; i < count; i++) {
        pairs[i].sensor = carom_body_id_unpack(get_u64(r, "sensor overlap"));
        pairs[i].other = carom_body_id_unpack(get_u64(r, "sensor overlap"));
        if (!r->failed && !carom_body_is_sensor(w, pairs[i].sensor)) {
            free(pairs);
            return bad(r, "sensor overlap %d names a body that is not a live sensor", i);
        }
    }
    if (r->failed) { free(pairs); return 0; }
    w->sensor_overlaps = pairs;
    w->sensor_overlap_count = count;
    w->sensor_overlap_capacity = count;
    return 1;
}

static int read_contact_list(reader *r, carom_world *w, int count, mix_memo *memo);

static int read_contacts(reader *r, carom_world *w, const int *class_of)
{
    contact_set *cs = &w->contacts;
    int count = get_small(r, 0, 1 << 28, 0, "contact count");
    if (r->failed) return 0;
    if ((size_t)count * 3 > r->size - r->pos) return bad(r, "truncated: %d contacts need more than the bytes left", count); /* (the shortest record: 3 bytes) */
    if (!contact_set_reserve(cs, count)) return no_memory(r);
    mix_memo *memo = malloc(sizeof *memo); /* (without it, every contact mixes its own) */
    if (memo) mix_memo_init(memo, class_of);
    int ok = read_contact_list(r, w, count, memo);
    free(memo);
    if (!ok) return 0;
    int repeated;
    if (!contact_set_index(cs, &repeated)) return no_memory(r);
    if (!r->reuse) contact_set_trim(cs); /* (a spare keeps its room for the next restore) */
    if (repeated >= 0) {
        const contact *c = &cs->items[repeated];
        return bad(r, "contact %d repeats the pair (%d, %d) manifold %u", repeated, c->id_a < c->id_b ? c->id_a : c->id_b,
                   c->id_a < c->id_b ? c->id_b : c->id_a, (unsigned)c->sub);
    }
    return 1;
}

static int read_contact_list(reader *r, carom_world *w, int count, mix_memo *memo)
{
    body_store *s = &w->bodies;
    contact_set *cs = &w->contacts;
    contact_data scratch_data; /* (a slotless pair's record: see below) */
    memset(&scratch_data, 0, sizeof scratch_data);
    contact_data *scratch = &scratch_data;
    int last_a = 0, old = r->version == 7; /* format 7: the lower id first, then bit CREC_B_FIRST */
    int64_t all_bits = old ? CREC_ALL_7 : CREC_ALL;
    for (int i = 0; i < count && !r->failed; i++) {
        int a, b;
        if (old) {
            a = last_a + get_small(r, -(int64_t)last_a, (int64_t)s->id_count - 2 - last_a, 1, "contact body");
            if (r->failed) return 0;
            b = a + 1 + get_small(r, 0, (int64_t)s->id_count - 2 - a, 0, "contact body");
        } else { /* body A's id, then B's from it (never A's) */
            a = last_a + get_small(r, -(int64_t)last_a, (int64_t)s->id_count - 1 - last_a, 1, "contact body A");
            if (r->failed) return 0;
            int64_t d = unzigzag((uint64_t)get_small(r, 0, 2 * (int64_t)s->id_count, 0, "contact body B") + 1);
            if (r->failed) return 0;
            if (a + d < 0 || a + d >= s->id_count)
                return bad(r, "contact %d: body B %lld is outside the id table [0, %d)", i, (long long)(a + d), s->id_count);
            b = (int)(a + d);
        }
        if (r->failed) return 0;
        last_a = a;
        if (s->ids[a].slot < 0 || s->ids[b].slot < 0)
            return bad(r, "contact %d joins ids %d and %d, not two live bodies", i, a, b);
        int head = get_small(r, 0, (all_bits << CONTACT_FLAG_BITS) | ((1 << CONTACT_FLAG_BITS) - 1), 0, "contact flags");
        uint32_t flags = (uint32_t)head & ((1u << CONTACT_FLAG_BITS) - 1);
        int bits = head >> CONTACT_FLAG_BITS;
        uint32_t sub = (bits & CREC_SUB) ? (uint32_t)get_small(r, 1, 1000000, 0, "contact sub") : 0;
        uint32_t sub_limit = (bits & CREC_SUB_LIMIT) ? (uint32_t)get_small(r, 1, 1000001, 0, "contact sub limit") : 0;
        int feature = (bits & CREC_FEATURE) ? get_small(r, 0, INT32_MAX, 1, "contact cache feature") : -1;
        if (r->failed) return 0;
        int posed = (flags & (CONTACT_REUSABLE | CONTACT_APART)) != 0;
        if ((flags & ~(uint32_t)CONTACT_KNOWN_FLAGS) || (bits & 7) > MANIFOLD_MAX_POINTS || (bits & CREC_FEATURE && feature == -1) ||
            ((bits & CREC_POSE) && !posed) || ((bits & CREC_REACH) && !(flags & CONTACT_APART)) ||
            ((bits & CREC_NORMAL_A) && !(flags & CONTACT_REUSABLE)))
            return bad(r, "contact %d has unknown flags, too many points or fields its flags do not use", i);
        if (bits & CREC_B_FIRST) { /* (format 7) body A first */
            int t = a;
            a = b;
            b = t;
            bits &= ~CREC_B_FIRST;
        }
        int ci = contact_append(cs, a, b, sub); /* (the pair map is built after the last, contact_set_index) */
        if (ci >= 0 && !(flags & IDLE_RECORD_FLAGS) && !(bits & ~(CREC_HAS_NORMAL | CREC_FLIP | CREC_FEATURE))) {
            /* a pair without data, not posed, of the first manifold (the
             * writer's short record): nothing more to read, and what the
             * general path below would check holds (its bits are its cache's) */
            contact *c = &cs->items[ci];
            c->flags = flags;
            c->cache.has_normal = (bits & CREC_HAS_NORMAL) != 0;
            c->cache.flip = (bits & CREC_FLIP) != 0;
            c->cache.feature = feature;
            continue;
        }
        /* a pair whose record has no points, normal, basis or material of its
         * own and no flag under which its data is read gets no data slot (it
         * reads the empty record, as collision.c leaves such a pair): its
         * record is read into scratch, which stays all zeros but for the
         * material (most broadphase pairs of a settled pile) */
        int keep = (flags & (CONTACT_TOUCHING | CONTACT_WAS_TOUCHING | CONTACT_ANY_TOUCHING | CONTACT_REUSABLE)) ||
                   (bits & (7 | CREC_NORMAL | CREC_TANGENT | CREC_TANGENT_GUESS | CREC_MATERIAL));
        if (ci < 0 || (keep && !contact_data_alloc(cs, ci))) return no_memory(r);
        contact *c = &cs->items[ci];
        contact_data *d = keep ? CONTACT_DATA(cs, ci) : scratch;
        int sa = s->ids[a].slot, sb = s->ids[b].slot;
        if (sub) { /* the compound children a manifold number names must exist (its material is theirs); sub 0 names child 0 */
            int child_a, child_b;
            compound_sub_children(&s->shapes[sa], &s->shapes[sb], sub, &child_a, &child_b);
            if ((child_a >= 0 && child_a >= s->shapes[sa].compound->count) || (child_b >= 0 && child_b >= s->shapes[sb].compound->count))
                return bad(r, "contact %d: manifold %u names a compound child the bodies do not have", i, (unsigned)sub);
        }
        contact_guess g = {&s->collided[sa], &s->collided[sb], {0, 0, 0}, 0, {0, 0, 0}};
        if (keep) guess_material(s, memo, sa, sb, sub, &g);
        c->flags = flags;
        c->sub_limit = sub_limit;
        c->cache.has_normal = (bits & CREC_HAS_NORMAL) != 0;
        c->cache.flip = (bits & CREC_FLIP) != 0;
        c->cache.feature = feature;
        d->m.count = bits & 7;
        vec3 normal = (d->m.count > 0 || (bits & CREC_NORMAL)) ? get_coded_v3(r, v3(0, 0, 0), "manifold normal") : v3(0, 0, 0);
        d->m.normal = normal;
        if (!r->failed && !v3_is_zero(normal) && !normal_is_state(c, d))
            return bad(r, "contact %d has a normal it does not use", i);
        vec3 cache_guess = c->cache.has_normal ? normal : v3(0, 0, 0);
        c->cache.normal = (bits & CREC_CACHE_NORMAL) ? get_coded_v3(r, cache_guess, "contact cache normal") : cache_guess;
        double material[3] = {g.material[0], g.material[1], g.material[2]};
        if (bits & CREC_MATERIAL) get_coded(r, material, g.material, 3, "contact material");
        d->friction = material[0];
        d->restitution = material[1];
        d->rolling_resistance = material[2];
        d->tangent1 = (bits & CREC_TANGENT)         ? get_coded_v3(r, guess_basis(&g, c), "friction basis")
                      : (bits & CREC_TANGENT_GUESS) ? guess_basis(&g, c) : v3(0, 0, 0);
        /* the predictions, as the writer made them */
        xform rel = posed ? relative_pose(*g.xa, *g.xb) : identity_pose;
        double reach = (flags & CONTACT_APART) ? body_reach(s, memo, sb) : 0.0;
        vec3 normal_a = (flags & CONTACT_REUSABLE) ? q_inv_rotate(g.xa->q, normal) : normal;
        if (posed) {
            c->rel_pose.p = (bits & CREC_POSE) ? get_coded_v3(r, rel.p, "contact pose") : rel.p;
            c->rel_pose.q = (bits & CREC_POSE) ? get_coded_q(r, rel.q, "contact pose") : rel.q;
        }
        if (flags & CONTACT_APART) {
            c->gap = get_coded1(r, 0.0, "contact gap");
            c->reach_b = (bits & CREC_REACH) ? get_coded1(r, reach, "contact reach") : reach;
        }
        if (flags & CONTACT_REUSABLE)
            d->normal_a = (bits & CREC_NORMAL_A) ? get_coded_v3(r, normal_a, "contact normal") : normal_a;
        if (r->failed) return 0;
        if (bad_direction(d->m.normal) || bad_direction(c->cache.normal) || bad_direction(d->tangent1) ||
            ((flags & CONTACT_REUSABLE) && bad_direction(d->normal_a)))
            return bad(r, "contact %d: a normal or friction basis of length outside [0.5, 2]", i);
        if (posed && (!within_cube(c->rel_pose.p, 2 * RANGE_STATE_COORDINATE_MAX) ||
                      !(q_len(c->rel_pose.q) >= 0.5 && q_len(c->rel_pose.q) <= 2.0)))
            return bad(r, "contact %d: the pose is beyond 2e18 m or its rotation not near unit", i);
        if ((contact_bits(c, d, &g, &normal, &cache_guess, &rel, reach, &normal_a) | (bits & CREC_EXACT)) != (unsigned)bits ||
            ((bits & CREC_EXACT) && d->m.count == 0))
            return bad(r, "contact %d: its record bits do not match its fields", i);
        if (!(d->friction >= 0 && d->friction <= RANGE_FRICTION_MAX && d->restitution >= 0 && d->restitution <= 1 &&
              d->rolling_resistance >= 0 && d->rolling_resistance <= RANGE_FRICTION_MAX))
            return bad(r, "contact %d material out of range", i);
        double last[7] = {0, 0, 0, 0, 0, 0, 0};
        reuse_motion m;
        reuse_guess(c, &rel, &m);
        int inexact = 0;
        for (int k = 0; k < d->m.count && !r->failed; k++) {
            manifold_point *p = &d->m.points[k];
            contact_point_state *st = &d->state[k];
            double cur[7];
            p->id = (uint32_t)get_small(r, 0, UINT32_MAX, 0, "manifold point id") ^ (k ? d->m.points[k - 1].id : 0u);
            get_coded(r, cur, last, 3, "contact point");
            get_coded(r, cur + 3, last + 3, 4, "contact point");
            st->local_a = v3(cur[0], cur[1], cur[2]);
            st->separation = cur[3];
            st->normal_impulse = cur[4];
            st->tangent_impulse[0] = cur[5];
            st->tangent_impulse[1] = cur[6];
            vec3 point;
            double separation;
            point_guess(&m, d, *g.xa, st, &point, &separation);
            p->point = (bits & CREC_EXACT) ? point : get_coded_v3(r, point, "manifold point");
            p->separation = (bits & CREC_EXACT) ? separation : get_coded1(r, separation, "manifold point");
            if (!same_bits(&point, &p->point, sizeof point) || f64_bits(separation) != f64_bits(p->separation)) inexact = 1;
            if (!(within_cube(p->point, RANGE_STATE_COORDINATE_MAX) && fabs(p->separation) <= RANGE_STATE_COORDINATE_MAX &&
                  within_cube(st->local_a, RANGE_STATE_COORDINATE_MAX) && fabs(st->separation) <= RANGE_STATE_COORDINATE_MAX))
                return bad(r, "contact %d: a point or separation is beyond 1e18 m (or not finite)", i);
            memcpy(last, cur, sizeof cur);
            /* warm-start impulses the solver could have stored (a fuzzed one of
             * 1.7e307 N s threw a hull 1.9e303 m in one step) */
            if (!r->failed && !(st->normal_impulse >= 0 && st->normal_impulse <= RANGE_IMPULSE_MAX &&
                                fabs(st->tangent_impulse[0]) <= RANGE_FRICTION_MAX * RANGE_IMPULSE_MAX &&
                                fabs(st->tangent_impulse[1]) <= RANGE_FRICTION_MAX * RANGE_IMPULSE_MAX))
                return bad(r, "contact %d: a warm-start impulse outside [0, 1e30] N s (tangent 1e33)", i);
        }
        /* one encoding per state: points all as predicted say so in the bits */
        if (!r->failed && d->m.count > 0 && !(bits & CREC_EXACT) && !inexact)
            return bad(r, "contact %d: its points are all as predicted but written", i);
        /* nothing a slotless pair would not read (collision.c): the slot goes
         * back, for the next contact */
        if (!r->failed && keep && contact_data_idle(cs, ci) && f64_bits(d->friction) == f64_bits(g.material[0]) &&
            f64_bits(d->restitution) == f64_bits(g.material[1]) && f64_bits(d->rolling_resistance) == f64_bits(g.material[2]))
            contact_data_release(cs, ci);
    }
    return !r->failed;
}

/* carom_world_restore, and why it refused: *status OUT_OF_MEMORY or
 * INVALID_ARGUMENT (the data). into: a world to read into (keeping its
 * memory), or NULL for a new one; it is destroyed when the data is refused. */
static carom_world *restore_world(const void *data, size_t size, char *msg, size_t msg_size, carom_world *into,
                                  carom_status *status);

/* A spare world emptied for the next state, its memory kept (everything a
 * new world would hold is reset; what the reader sets is left to it). */
static void clear_state(carom_world *w)
{
    body_store *s = &w->bodies;
    for (int i = 0; i < s->count; i++) shape_free_data(&s->shapes[i]);
    s->count = 0;
    bp_clear(w->bp);
    contact_set_clear(&w->contacts);
    free(w->sensor_overlaps);
    w->sensor_overlaps = NULL;
    w->sensor_overlap_count = w->sensor_overlap_capacity = 0;
    w->events.count = 0;
    w->stats = carom_world_stats_init();
    w->filters_settled = 0;
    w->pair_filter = NULL;
    w->pair_filter_context = NULL;
    w->pre_solve = NULL;
    w->pre_solve_context = NULL;
}

CAROM_API carom_world *carom_world_restore(const void *data, size_t size, char *msg, size_t msg_size)
{
    carom_status status;
    return restore_world(data, size, msg, msg_size, NULL, &status);
}

/* Double-buffered: the new state is read into a world of its own (the
 * spare, which holds the state before the last restore: its pages are
 * already the process's, where a new world's would be fresh, about 3,800
 * page faults for the bench's 10,000 bodies), so a refused snapshot leaves
 * w as it was; on success w and the spare exchange states (w keeps its
 * address, the host's handle, and its step scratch) and the old state
 * becomes the spare. A refused snapshot costs the spare (the next restore
 * makes a new one). The host's settings are not state and stay: the event
 * callback, the task hooks, the pair filter and pre-solve callbacks, the
 * last error, and the user data of every body the snapshot also holds (the
 * same id and generation). */
CAROM_API carom_status carom_world_restore_into(carom_world *w, const void *data, size_t size)
{
    if (!w) return CAROM_ERROR_INVALID_ARGUMENT;
    if (w->locked)
        return world_fail(w, CAROM_ERROR_LOCKED, "world_restore_into: the world is inside its step; restore it afterwards");
    char msg[WORLD_ERROR_SIZE];
    carom_status status = CAROM_OK;
    carom_world *spare = w->spare;
    w->spare = NULL; /* (restore_world destroys it if the data is refused) */
    carom_world *n = restore_world(data, size, msg, sizeof msg, spare, &status);
    if (!n) return world_fail(w, status, "world_restore_into: %s", msg);
    n->def.event_callback = w->def.event_callback;
    n->def.event_context = w->def.event_context;
    n->def.worker_count = w->def.worker_count;
    n->def.enqueue_task = w->def.enqueue_task;
    n->def.finish_task = w->def.finish_task;
    n->def.task_context = w->def.task_context;
    n->pair_filter = w->pair_filter;
    n->pair_filter_context = w->pair_filter_context;
    n->pre_solve = w->pre_solve;
    n->pre_solve_context = w->pre_solve_context;
    const body_store *old = &w->bodies;
    body_store *now = &n->bodies;
    for (int i = 0; i < old->id_count && i < now->id_count; i++) {
        int from = old->ids[i].slot, to = now->ids[i].slot;
        if (from >= 0 && to >= 0 && old->ids[i].generation == now->ids[i].generation) now->user_data[to] = old->user_data[from];
    }
    /* the states change places; the scratch, events buffer and last error stay */
#define SWAP(field) do { swap.field = w->field; w->field = n->field; n->field = swap.field; } while (0)
    carom_world swap;
    SWAP(def);
    SWAP(bodies);
    SWAP(bp);
    SWAP(contacts);
    SWAP(stats);
    SWAP(filters_settled);
    SWAP(sensor_overlaps);
    SWAP(sensor_overlap_count);
    SWAP(sensor_overlap_capacity);
#undef SWAP
    w->events.count = 0; /* (the last step's events are not state) */
    n->pair_filter = NULL; /* (the spare never steps) */
    n->pair_filter_context = NULL;
    n->pre_solve = NULL;
    n->pre_solve_context = NULL;
    w->spare = n;
    return CAROM_OK;
}

static carom_world *read_world(reader *r);

static carom_world *restore_world(const void *data, size_t size, char *msg, size_t msg_size, carom_world *into,
                                  carom_status *status)
{
    reader r = {data, size, 0, msg, msg_size, 0, SNAP_VERSION, 0, into, 0};
    *status = CAROM_ERROR_INVALID_ARGUMENT;
    carom_world *w = read_world(&r);
    carom_world_destroy(r.into); /* (refused before read_world took it) */
    if (!w && r.out_of_memory) *status = CAROM_ERROR_OUT_OF_MEMORY;
    return w;
}

static carom_world *read_world(reader *r)
{
    const void *data = r->buf;
    size_t size = r->size;
    if (r->msg && r->msg_size) r->msg[0] = '\0';
    if (!data) return bad(r, "data is NULL"), NULL;
    if (size < SNAP_HEADER_SIZE || memcmp(data, SNAP_MAGIC, 8) != 0)
        return bad(r, "not a carom snapshot (no \"" SNAP_MAGIC "\" header)"), NULL;
    r->pos = 8;
    uint32_t version = get_u32(r, "version"), header = get_u32(r, "header size");
    uint64_t total = get_u64(r, "size"), sum = get_u64(r, "checksum");
    if (version < SNAP_VERSION_OLDEST || version > SNAP_VERSION)
        return bad(r, "version %u; this carom reads versions %u to %u", (unsigned)version, SNAP_VERSION_OLDEST, SNAP_VERSION), NULL;
    r->version = version;
    if (header != SNAP_HEADER_SIZE) return bad(r, "header size %u, expected %u", (unsigned)header, SNAP_HEADER_SIZE), NULL;
    if (total != size)
        return bad(r, "truncated or padded: the header says %llu bytes, %zu given", (unsigned long long)total, size), NULL;
    if (checksum(r->buf + SNAP_HEADER_SIZE, size - SNAP_HEADER_SIZE) != sum)
        return bad(r, "corrupted (checksum mismatch)"), NULL;

    carom_world_def def;
    read_def(r, &def);
    double last_dt = get_f64(r, "reserved f64"); /* was the last step's dt: read, checked, unused */
    uint64_t steps = get_u64(r, "step count");
    if (r->failed) return NULL;
    char why[WORLD_ERROR_SIZE];
    if (carom_world_def_check(&def, why, sizeof why) != CAROM_OK) return bad(r, "settings: %s", why), NULL;
    /* written as 0 (it was the last step's dt): anything else would not
     * snapshot back to the same bytes */
    if (last_dt != 0.0) return bad(r, "reserved field after the settings is %g, not 0", last_dt), NULL;
    if (steps >> 63) return bad(r, "step count out of range"), NULL;
    /* the storage hint is kept but not acted on: the store is sized for the
     * bodies the snapshot holds, never for a number the data merely claims */
    int capacity_hint = def.body_capacity;
    def.body_capacity = 0;
    carom_world *w = r->into; /* (taken: destroyed below if the data is refused) */
    r->into = NULL;
    r->reuse = w != NULL;
    if (!w) w = carom_world_create(&def);
    if (!w) return no_memory(r), NULL;
    if (r->reuse) {
        clear_state(w);
        w->def = def; /* (as carom_world_create keeps a checked def) */
    }
    w->def.body_capacity = capacity_hint;
    w->stats.step_count = (long long)steps;
    int *class_of = NULL;
    if (!read_bodies(r, w, &class_of)) {
        free(class_of);
        carom_world_destroy(w);
        return NULL;
    }
    body_store *s = &w->bodies;
    int ok = read_contacts(r, w, class_of) && read_sensor_overlaps(r, w);
    free(class_of);
    if (!ok) {
        carom_world_destroy(w);
        return NULL;
    }
    if (r->pos != size) {
        carom_world_destroy(w);
        return bad(r, "%zu bytes left over after the sensor overlaps", size - r->pos), NULL;
    }
    /* the broadphase, built at once from the stored bounds (the trees' shape
     * does not change what it reports), with the moved set restored */
    int *is_static = malloc(sizeof *is_static * (size_t)(s->count > 0 ? s->count : 1));
    ok = is_static != NULL;
    for (int i = 0; ok && i < s->count; i++) is_static[i] = s->type[i] == CAROM_BODY_STATIC;
    ok = ok && bp_create_proxies(w->bp, s->fat_box, is_static, s->id_index, s->count, s->proxy);
    free(is_static);
    if (!ok) {
        carom_world_destroy(w);
        return no_memory(r), NULL;
    }
    for (int i = 0; i < s->count; i++) {
        bp_set_moved(w->bp, s->proxy[i], s->solver_index[i]);
        s->solver_index[i] = -1;
    }
    return w;
}
