/* carom_threads.h - a reference implementation of carom_world_def's task
 * hooks on POSIX threads: a pool of worker threads that a world (or several,
 * one step at a time) hands its ranges to. Optional: a host with its own job
 * system sets the hooks itself (see carom_task_fn in carom.h).
 *
 *     carom_thread_pool *pool = carom_thread_pool_create(4);
 *     carom_world_def def = carom_world_def_default();
 *     carom_thread_pool_attach(pool, &def);   // worker_count 4 and the hooks
 *     carom_world *world = carom_world_create(&def);
 *     ...
 *     carom_world_destroy(world);
 *     carom_thread_pool_destroy(pool);        // after every world using it
 */
#ifndef CAROM_THREADS_H
#define CAROM_THREADS_H

#include "carom/carom.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct carom_thread_pool carom_thread_pool;

/* A pool of `workers` workers (1..CAROM_MAX_WORKERS): workers - 1 threads,
 * and the thread that waits for a task works too. NULL when workers is
 * outside the range or the threads cannot be started. */
CAROM_API carom_thread_pool *carom_thread_pool_create(int workers);
/* Stops and joins the threads; NULL is ignored. No world may be stepping. */
CAROM_API void carom_thread_pool_destroy(carom_thread_pool *pool);
CAROM_API int carom_thread_pool_workers(const carom_thread_pool *pool);
/* Sets def's worker_count, enqueue_task, finish_task and task_context to the
 * pool's (def->size must cover them: a def from carom_world_def_default()). */
CAROM_API carom_status carom_thread_pool_attach(carom_thread_pool *pool, carom_world_def *def);
/* The hooks themselves (task_context is the pool). One task runs at a time
 * per pool; a task enqueued while another is running runs inline. */
CAROM_API void *carom_thread_pool_enqueue(carom_task_fn *task, int item_count, int min_range, void *task_data,
                                          void *pool);
CAROM_API void carom_thread_pool_finish(void *task, void *pool);

/* Checks a worker count for carom_thread_pool_create: CAROM_OK for
 * 1..CAROM_MAX_WORKERS, else CAROM_ERROR_INVALID_ARGUMENT with the reason
 * in msg (if not NULL). */
CAROM_API carom_status carom_thread_pool_check(int workers, char *msg, size_t msg_size);

#ifdef __cplusplus
}
#endif

#endif
