/* sim/event.h -- the timing model's event queue: a binary heap ordered by (time, insertion).
 *
 * Owns: ordering of future events. Must not: know what an event means (sim/timing.c does).
 * Ties are broken by insertion order, so a run is deterministic.
 */
#ifndef SFSIM_EVENT_H
#define SFSIM_EVENT_H

#include <stddef.h>
#include <stdint.h>

typedef struct EvEvent {
    uint64_t time;    /* cycle at which the event happens */
    uint64_t seq;     /* insertion number: breaks ties */
    uint32_t tag;     /* the owner's check that the event is still current (e.g. a writer number) */
    uint16_t arg;     /* what it applies to (a register, a unit) */
    uint8_t kind;     /* the owner's event kind */
    uint8_t cause;    /* the stall cause charged while something waits for it */
} EvEvent;

typedef struct EvQueue {
    EvEvent *h;
    size_t n, cap;
    uint64_t seq;
} EvQueue;

void evq_init(EvQueue *q);
void evq_free(EvQueue *q);
void evq_clear(EvQueue *q);
/* Returns 0, or -1 when memory runs out. */
int evq_push(EvQueue *q, uint64_t time, uint8_t kind, uint16_t arg, uint32_t tag, uint8_t cause);
static inline const EvEvent *evq_top(const EvQueue *q) { return q->n ? &q->h[0] : NULL; }
void evq_pop(EvQueue *q);

#endif
