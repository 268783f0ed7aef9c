/* tasks.h - ranges of work through the host's task hooks (carom_world_def's
 * enqueue_task / finish_task). A stage hands over a loop whose items are
 * independent: each item writes only its own outputs, so any split into
 * ranges, run in any order on any workers, gives the same bits. Anything
 * that combines items (a sum, a list) is written per item and merged in item
 * order afterwards, on the calling thread. */
#ifndef CAROM_TASKS_H
#define CAROM_TASKS_H

#include "carom/carom.h"

/* Runs fn over items 0 .. count-1: on the calling thread in one range
 * (0, count, worker 0) when the world has no hooks, one worker or at most
 * min_range items; else through the hooks in ranges of at least min_range.
 * In builds without NDEBUG an assertion stops a hook that runs an item
 * twice, skips one, or passes a range or worker index out of bounds. */
void tasks_run(const carom_world_def *def, int count, int min_range, carom_task_fn *fn, void *data);

/* Workers a stage may see (per-worker scratch is sized by it). */
int tasks_workers(const carom_world_def *def);

#endif
