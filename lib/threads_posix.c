/* threads_posix.c - the reference task hooks (carom_threads.h): a pool of
 * POSIX threads. Workers and the thread waiting in finish claim a task's
 * items a range at a time under the pool's lock, each range a share of
 * what is left (guided scheduling, never under min_range). A thread with
 * nothing to do polls briefly for the next task (or, in finish, for the last
 * range) before it blocks: a step hands over some 150 tasks back to back
 * (a pass per colour per sub-step), and waking a blocked thread costs tens
 * of microseconds, more on a virtual machine. */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <sched.h>
#include <time.h>
#include <stdio.h>
#include <stdlib.h>
#include "carom/carom_threads.h"

/* A claim takes 1/(SHARE_PER_WORKER x workers) of the items left: the
 * first ranges are long (few claims), the last ones min_range short, so
 * the task's tail (one worker busy, the rest waiting) is short too. Fixed
 * eighths per worker left a tail of up to an eighth of a worker's share:
 * on the 50,000-body grid's colour passes (2 workers), some 0.25 ms of a
 * 4 ms pass. A claim costs a lock, far below a range's work (min_range
 * sees to that). */
#define SHARE_PER_WORKER 2
/* How long a thread with nothing to claim polls before it blocks: longer
 * than the gap between two passes of a step, far shorter than a frame's
 * gap between steps. The first polls pause; later ones yield the core, so
 * that on a machine with more runnable threads than cores a poller gives
 * its time to the threads with work. */
#define POLL_NS 100000L
#define POLLS_PAUSING 64

struct carom_thread_pool {
    int workers;
    int threads_started;
    pthread_t threads[CAROM_MAX_WORKERS];
    pthread_mutex_t lock;
    pthread_cond_t work_ready;   /* a task was enqueued, or stop */
    pthread_cond_t work_done;    /* the last range of the task finished */
    /* the task in flight (busy), under lock */
    carom_task_fn *task;
    void *task_data;
    int item_count, min_range;
    int next_item, done_items;
    int busy, stop;
    int task_seq; /* counts enqueued tasks (and the stop): what a polling worker watches */
};

/* One poll's wait: tells the core (and a hyperthread sibling) that this is a spin. */
static void cpu_relax(void)
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

static long elapsed_ns(const struct timespec *t0)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (long)(t.tv_sec - t0->tv_sec) * 1000000000L + (t.tv_nsec - t0->tv_nsec);
}

/* Polls *word, which other threads change under the pool's lock (with an
 * atomic store, so this unlocked read is not a race), until it differs from
 * seen: 1 when it did within POLL_NS, else 0. Called without the lock. */
static int poll_for_change(const int *word, int seen)
{
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int i = 0;; i++) {
        if (__atomic_load_n(word, __ATOMIC_ACQUIRE) != seen) return 1;
        if (i < POLLS_PAUSING) {
            cpu_relax();
            continue;
        }
        if (elapsed_ns(&t0) > POLL_NS) return 0;
        sched_yield();
    }
}

/* Claims and runs ranges of the task in flight until none is left; called
 * and returns with the lock held. */
static void work_on_task(carom_thread_pool *p, int worker)
{
    while (p->busy && p->next_item < p->item_count) {
        int begin = p->next_item, left = p->item_count - begin;
        int size = (left + SHARE_PER_WORKER * p->workers - 1) / (SHARE_PER_WORKER * p->workers);
        if (size < p->min_range) size = p->min_range;
        int end = size < left ? begin + size : p->item_count;
        p->next_item = end;
        carom_task_fn *task = p->task;
        void *data = p->task_data;
        pthread_mutex_unlock(&p->lock);
        task(begin, end, worker, data);
        pthread_mutex_lock(&p->lock);
        if (__atomic_add_fetch(&p->done_items, end - begin, __ATOMIC_RELEASE) == p->item_count)
            pthread_cond_signal(&p->work_done);
    }
}

typedef struct worker_start {
    carom_thread_pool *pool;
    int worker;
} worker_start;

static void *worker_main(void *arg)
{
    worker_start *start = arg;
    carom_thread_pool *p = start->pool;
    int worker = start->worker;
    free(start);
    pthread_mutex_lock(&p->lock);
    for (;;) {
        if (p->stop) break;
        if (p->busy && p->next_item < p->item_count) {
            work_on_task(p, worker);
            continue;
        }
        /* nothing to claim: poll for the next task, then block (re-checked
         * under the lock, so an enqueue between the two is never missed) */
        int seen = p->task_seq;
        pthread_mutex_unlock(&p->lock);
        int changed = poll_for_change(&p->task_seq, seen);
        pthread_mutex_lock(&p->lock);
        if (!changed && p->task_seq == seen) pthread_cond_wait(&p->work_ready, &p->lock);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

CAROM_API carom_status carom_thread_pool_check(int workers, char *msg, size_t msg_size)
{
    int ok = workers >= 1 && workers <= CAROM_MAX_WORKERS;
    if (msg && msg_size) {
        if (ok) msg[0] = '\0';
        else snprintf(msg, msg_size, "workers must be in 1..%d (got %d)", CAROM_MAX_WORKERS, workers);
    }
    return ok ? CAROM_OK : CAROM_ERROR_INVALID_ARGUMENT;
}

CAROM_API carom_thread_pool *carom_thread_pool_create(int workers)
{
    if (carom_thread_pool_check(workers, NULL, 0) != CAROM_OK) return NULL;
    carom_thread_pool *p = calloc(1, sizeof *p);
    if (!p) return NULL;
    p->workers = workers;
    if (pthread_mutex_init(&p->lock, NULL) != 0) { free(p); return NULL; }
    if (pthread_cond_init(&p->work_ready, NULL) != 0) {
        pthread_mutex_destroy(&p->lock);
        free(p);
        return NULL;
    }
    if (pthread_cond_init(&p->work_done, NULL) != 0) {
        pthread_cond_destroy(&p->work_ready);
        pthread_mutex_destroy(&p->lock);
        free(p);
        return NULL;
    }
    for (int k = 1; k < workers; k++) {
        worker_start *start = malloc(sizeof *start);
        if (!start) break;
        start->pool = p;
        start->worker = k;
        if (pthread_create(&p->threads[p->threads_started], NULL, worker_main, start) != 0) {
            free(start);
            break;
        }
        p->threads_started++;
    }
    if (p->threads_started != workers - 1) {
        carom_thread_pool_destroy(p);
        return NULL;
    }
    return p;
}

CAROM_API void carom_thread_pool_destroy(carom_thread_pool *p)
{
    if (!p) return;
    pthread_mutex_lock(&p->lock);
    p->stop = 1;
    __atomic_store_n(&p->task_seq, p->task_seq + 1, __ATOMIC_RELEASE);
    pthread_cond_broadcast(&p->work_ready);
    pthread_mutex_unlock(&p->lock);
    for (int k = 0; k < p->threads_started; k++) pthread_join(p->threads[k], NULL);
    pthread_cond_destroy(&p->work_done);
    pthread_cond_destroy(&p->work_ready);
    pthread_mutex_destroy(&p->lock);
    free(p);
}

CAROM_API int carom_thread_pool_workers(const carom_thread_pool *p)
{
    return p ? p->workers : 0;
}

CAROM_API carom_status carom_thread_pool_attach(carom_thread_pool *p, carom_world_def *def)
{
    if (!p || !def || def->size < offsetof(carom_world_def, task_context) + sizeof(void *))
        return CAROM_ERROR_INVALID_ARGUMENT;
    def->worker_count = p->workers;
    def->enqueue_task = carom_thread_pool_enqueue;
    def->finish_task = carom_thread_pool_finish;
    def->task_context = p;
    return CAROM_OK;
}

CAROM_API void *carom_thread_pool_enqueue(carom_task_fn *task, int item_count, int min_range, void *task_data,
                                          void *pool)
{
    carom_thread_pool *p = pool;
    if (item_count <= 0) return NULL;
    if (min_range < 1) min_range = 1;
    pthread_mutex_lock(&p->lock);
    if (p->busy || p->workers == 1) {
        /* one task at a time: this one runs here, now */
        pthread_mutex_unlock(&p->lock);
        task(0, item_count, 0, task_data);
        return NULL;
    }
    p->task = task;
    p->task_data = task_data;
    p->item_count = item_count;
    p->min_range = min_range;
    p->next_item = 0;
    __atomic_store_n(&p->done_items, 0, __ATOMIC_RELAXED);
    p->busy = 1;
    __atomic_store_n(&p->task_seq, p->task_seq + 1, __ATOMIC_RELEASE);
    pthread_cond_broadcast(&p->work_ready);
    pthread_mutex_unlock(&p->lock);
    return p;
}

CAROM_API void carom_thread_pool_finish(void *task, void *pool)
{
    carom_thread_pool *p = pool;
    if (!task) return;
    pthread_mutex_lock(&p->lock);
    work_on_task(p, 0); /* the waiting thread is worker 0 */
    while (p->done_items < p->item_count) {
        /* the last ranges run elsewhere: poll for them, then block */
        int done = p->done_items;
        pthread_mutex_unlock(&p->lock);
        int changed = poll_for_change(&p->done_items, done);
        pthread_mutex_lock(&p->lock);
        if (!changed && p->done_items == done) pthread_cond_wait(&p->work_done, &p->lock);
    }
    p->busy = 0;
    pthread_mutex_unlock(&p->lock);
}
