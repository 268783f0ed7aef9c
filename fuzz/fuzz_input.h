/* fuzz_input.h - the fuzzers' input as a stream of choices: bytes become
 * small integers, booleans and numbers drawn from the values that matter
 * (range edges, zero, negatives, NaN, infinities, denormals, raw bit
 * patterns). Reading past the end yields zeros, so every input is a program. */
#ifndef CAROM_FUZZ_INPUT_H
#define CAROM_FUZZ_INPUT_H

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef struct fuzz_input {
    const uint8_t *p;
    size_t n, at;
} fuzz_input;

static inline unsigned fz_byte(fuzz_input *in) { return in->at < in->n ? in->p[in->at++] : 0u; }
static inline int fz_done(const fuzz_input *in) { return in->at >= in->n; }
static inline unsigned fz_below(fuzz_input *in, unsigned n) { return n ? fz_byte(in) % n : 0u; }
static inline int fz_bool(fuzz_input *in) { return (int)(fz_byte(in) & 1u); }

static inline double fz_raw_double(fuzz_input *in)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++) v = (v << 8) | fz_byte(in);
    double d;
    memcpy(&d, &v, sizeof d);
    return d;
}

/* A number in [lo, hi] (log-uniform when both are positive and far apart). */
static inline double fz_in(fuzz_input *in, double lo, double hi)
{
    double hi8 = fz_byte(in); /* one read per statement: C leaves the order within an expression open */
    double u = (hi8 * 256.0 + fz_byte(in)) / 65535.0;
    if (lo > 0 && hi / lo > 100) return exp(log(lo) + u * (log(hi) - log(lo)));
    return lo + u * (hi - lo);
}

/* Three numbers read in order. */
#define FZ_VEC3(out, expr) do { (out).x = (expr); (out).y = (expr); (out).z = (expr); } while (0)

/* Any double, biased to the interesting ones. */
static inline double fz_any(fuzz_input *in)
{
    static const double special[] = {
        0.0, -0.0, 1.0, -1.0, 0.5, 1e-6, 1e6, 1e-9, 1e15, 1e12, -1e12, 1e9, 4000.0, 1000.0, 1e4, -1e4,
        1e-3, 1e3, 1e-24, 1e30, 1e20, 1e100, -1e100, 1e-100, 1e300, DBL_MAX, -DBL_MAX, DBL_MIN, 4.9e-324,
        1e-5, 0.02, 9.81, 1.0 / 60.0, 1e-7};
    unsigned k = fz_byte(in);
    if (k < 64) return special[k % (sizeof special / sizeof special[0])] * (k & 32 ? -1 : 1);
    if (k < 72) return k & 1 ? INFINITY : -INFINITY;
    if (k < 76) return NAN;
    if (k < 90) {
        double v = fz_any(in);
        return nextafter(v, k & 1 ? INFINITY : -INFINITY); /* just past an edge */
    }
    if (k < 110) return fz_raw_double(in);
    return fz_in(in, -10.0, 10.0);
}

#endif
