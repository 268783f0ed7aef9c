/* fuzz_snapshot.c - libFuzzer harness for the snapshot reader. The input is
 * a snapshot; unless its first byte after the header's version says to keep
 * it raw, the header's size and checksum are rewritten to match, so the
 * fuzzer reaches the structural checks behind them. Invariants: no sanitizer
 * report; a refused input has a "snapshot: " message; an accepted one steps
 * with everything finite and snapshots back to exactly its own bytes (a
 * format-7 one, still read, to format-8 bytes that read back to themselves). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "carom/carom.h"
#include "fuzz_common.h"

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
    free(again);
    for (int i = 0; i < 3; i++) {
        if (carom_world_step(w, 1.0 / 60) != CAROM_OK) break;
        fuzz_assert_world_finite(w);
    }
    carom_world_destroy(w);
    free(copy);
    return 0;
}
