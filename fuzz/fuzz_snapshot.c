/* fuzz_snapshot.c - libFuzzer harness for the snapshot reader. The input is
 * a snapshot; unless its first byte after the header's version says to keep
 * it raw, the header's size and checksum are rewritten to match, so the
 * fuzzer reaches the structural checks behind them. Invariants: no sanitizer
 * report; a refused input has a "snapshot: " message; an accepted one steps
 * with everything finite and snapshots back to exactly its own bytes (a
 * format-7 one, still read, to format-8 bytes that read back to themselves).
 * carom_world_restore_into takes every input as carom_world_restore does,
 * and a refused one leaves its world unchanged. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "carom/carom.h"
#include "fuzz_common.h"

/* A world's snapshot, malloc'd (*n its size). */
static uint8_t *snapshot_of(const carom_world *w, size_t *n)
{
    *n = carom_world_snapshot(w, NULL, 0);
    uint8_t *b = malloc(*n ? *n : 1);
    if (!b || carom_world_snapshot(w, b, *n) != *n) abort();
    return b;
}

/* carom_world_restore_into a world that holds another state (a box on a
 * plane, stepped): twice, so the second reads into the first's spare. A
 * refused input must leave the world's snapshot as it was, with the
 * reader's reason; an accepted one must make it the snapshot's world (its
 * snapshot `expect`). */
static void check_restore_into(const uint8_t *input, size_t size, const uint8_t *expect, size_t expect_size)
{
    carom_world_def wd = carom_world_def_default();
    carom_world *w = carom_world_create(&wd);
    if (!w) abort();
    carom_body_def b = carom_body_def_default();
    b.type = CAROM_BODY_STATIC;
    b.shape = carom_shape_plane(0, 0, 1, 0);
    carom_body_create(w, &b);
    b = carom_body_def_default();
    b.position.z = 0.5;
    carom_body_create(w, &b);
    carom_world_step(w, 1.0 / 60);
    for (int round = 0; round < 2; round++) {
        size_t before_size;
        uint8_t *before = snapshot_of(w, &before_size);
        carom_status st = carom_world_restore_into(w, input, size);
        size_t after_size;
        uint8_t *after = snapshot_of(w, &after_size);
        if (!expect) {
            if (st == CAROM_OK || strncmp(carom_world_last_error(w), "world_restore_into: snapshot: ", 30) != 0) {
                fprintf(stderr, "restore_into: a refused snapshot was not refused with its reason: %s\n", carom_world_last_error(w));
                abort();
            }
            if (after_size != before_size || memcmp(after, before, after_size) != 0) {
                fprintf(stderr, "restore_into: a refused snapshot changed the world\n");
                abort();
            }
        } else if (st != CAROM_OK || after_size != expect_size || memcmp(after, expect, expect_size) != 0) {
            fprintf(stderr, "restore_into: an accepted snapshot did not become the world (%s)\n", carom_world_last_error(w));
            abort();
        }
        free(before);
        free(after);
    }
    carom_world_destroy(w);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > (1u << 22)) return 0;
    uint8_t *copy = malloc(size ? size : 1);
    if (!copy) return 0;
    memcpy(copy, data, size);
    int raw = size % 7 == 3; /* one input in seven is read as it is: the header checks too */
    if (!raw && size >= 32) fuzz_fix_snapshot_header(copy, size);
    char msg[256];
    carom_world *w = carom_world_restore(copy, size, msg, sizeof msg);
    if (!w) {
        if (strncmp(msg, "snapshot: ", 10) != 0) { fprintf(stderr, "refused without a message: %s\n", msg); abort(); }
        check_restore_into(copy, size, NULL, 0);
        free(copy);
        return 0;
    }
    size_t n = carom_world_snapshot(w, NULL, 0);
    uint8_t *again = malloc(n);
    if (!again || carom_world_snapshot(w, again, n) != n) abort();
    if (copy[8] == 7) {
        /* a format-7 input (still read) snapshots as the current format:
         * that must read back to exactly its own bytes */
        carom_world *w8 = carom_world_restore(again, n, msg, sizeof msg);
        if (!w8) { fprintf(stderr, "a format-7 input's own snapshot is refused: %s\n", msg); abort(); }
        uint8_t *twice = malloc(n);
        if (!twice || carom_world_snapshot(w8, twice, n) != n || memcmp(twice, again, n) != 0) {
            fprintf(stderr, "a format-7 input's snapshot does not snapshot back to itself\n");
            abort();
        }
        free(twice);
        carom_world_destroy(w8);
    } else if (n != size || memcmp(again, copy, n) != 0) {
        fprintf(stderr, "restore then snapshot is not the input\n");
        abort();
    }
    check_restore_into(copy, size, again, n);
    free(again);
    for (int i = 0; i < 3; i++) {
        if (carom_world_step(w, 1.0 / 60) != CAROM_OK) break;
        fuzz_assert_world_finite(w);
    }
    carom_world_destroy(w);
    free(copy);
    return 0;
}
