/* tasks.c - tasks_run: a loop through the host's task hooks, with the hooks'
 * contract checked in debug builds. */
#include <assert.h>
#include <stdint.h>
#include "tasks.h"

int tasks_workers(const carom_world_def *def)
{
    return def && def->enqueue_task ? def->worker_count : 1;
}

#ifndef NDEBUG
/* What the ranges a hook ran covered, counted per worker (so that workers
 * running at once never write the same slot): the items, their sum and the
 * sum of their squares (mod 2^64). Each item exactly once gives count,
 * count (count-1) / 2 and the sum of squares below count; an item run twice
 * or skipped changes the count, and an overlap traded for a gap of the same
 * size changes one of the two sums (the three agree only for the right
 * multiset in every case but contrived ones). */
typedef struct task_check {
    carom_task_fn *fn;
    void *data;
    int count, workers;
    uint64_t items[CAROM_MAX_WORKERS], sum[CAROM_MAX_WORKERS], sum_sq[CAROM_MAX_WORKERS];
} task_check;

/* sum of i for 0 <= i < x, and of i^2 (exact divisions first, then mod 2^64 products) */
static uint64_t sum_below(uint64_t x)
{
    if (x == 0) return 0;
    return x % 2 == 0 ? (x / 2) * (x - 1) : x * ((x - 1) / 2);
}

static uint64_t sum_sq_below(uint64_t x)
{
    if (x == 0) return 0;
    uint64_t a = x - 1, b = x, c = 2 * x - 1;
    if (a % 2 == 0) a /= 2; else b /= 2;
    if (a % 3 == 0) a /= 3; else if (b % 3 == 0) b /= 3; else c /= 3;
    return a * b * c;
}

static void checked_range(int begin, int end, int worker, void *p)
{
    task_check *t = p;
    assert(0 <= begin && begin < end && end <= t->count && "task hook: range outside the task's items");
    assert(0 <= worker && worker < t->workers && "task hook: worker index outside 0..worker_count-1");
    t->items[worker] += (uint64_t)(end - begin);
    t->sum[worker] += sum_below((uint64_t)end) - sum_below((uint64_t)begin);
    t->sum_sq[worker] += sum_sq_below((uint64_t)end) - sum_sq_below((uint64_t)begin);
    t->fn(begin, end, worker, t->data);
}

static void run_checked(const carom_world_def *def, int count, int min_range, carom_task_fn *fn, void *data)
{
    task_check t;
    t.fn = fn;
    t.data = data;
    t.count = count;
    t.workers = def->worker_count;
    for (int k = 0; k < t.workers; k++) t.items[k] = t.sum[k] = t.sum_sq[k] = 0;
    void *handle = def->enqueue_task(checked_range, count, min_range, &t, def->task_context);
    if (handle) def->finish_task(handle, def->task_context);
    uint64_t items = 0, sum = 0, sum_sq = 0;
    for (int k = 0; k < t.workers; k++) {
        items += t.items[k];
        sum += t.sum[k];
        sum_sq += t.sum_sq[k];
    }
    assert(items == (uint64_t)count && "task hook: an item ran twice or not at all (count)");
    assert(sum == sum_below((uint64_t)count) && sum_sq == sum_sq_below((uint64_t)count) &&
           "task hook: an item ran twice or not at all (coverage)");
    (void)items; (void)sum; (void)sum_sq;
}
#endif

void tasks_run(const carom_world_def *def, int count, int min_range, carom_task_fn *fn, void *data)
{
    if (count <= 0) return;
    if (min_range < 1) min_range = 1;
    if (!def || !def->enqueue_task || def->worker_count <= 1 || count <= min_range) {
        fn(0, count, 0, data);
        return;
    }
#ifndef NDEBUG
    run_checked(def, count, min_range, fn, data);
#else
    void *handle = def->enqueue_task(fn, count, min_range, data, def->task_context);
    if (handle) def->finish_task(handle, def->task_context);
#endif
}
