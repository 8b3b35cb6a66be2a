/* sim/event.c -- binary heap of timing events (see event.h). */
#include "event.h"

#include <stdlib.h>

void evq_init(EvQueue *q)
{
    q->h = NULL;
    q->n = q->cap = 0;
    q->seq = 0;
}

void evq_free(EvQueue *q)
{
    free(q->h);
    evq_init(q);
}

void evq_clear(EvQueue *q)
{
    q->n = 0;
    q->seq = 0;
}

static inline int before(const EvEvent *a, const EvEvent *b)
{
    return a->time < b->time || (a->time == b->time && a->seq < b->seq);
}

int evq_push(EvQueue *q, uint64_t time, uint8_t kind, uint16_t arg, uint32_t tag, uint8_t cause)
{
    if (q->n == q->cap) {
        size_t cap = q->cap ? 2 * q->cap : 64;
        EvEvent *h = realloc(q->h, cap * sizeof *h);
        if (!h)
            return -1;
        q->h = h;
        q->cap = cap;
    }
    EvEvent e = {time, q->seq++, tag, arg, kind, cause};
    size_t i = q->n++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (!before(&e, &q->h[p]))
            break;
        q->h[i] = q->h[p];
        i = p;
    }
    q->h[i] = e;
    return 0;
}

void evq_pop(EvQueue *q)
{
    if (q->n == 0)
        return;
    EvEvent last = q->h[--q->n];
    size_t i = 0, n = q->n;
    for (;;) {
        size_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && before(&q->h[c + 1], &q->h[c]))
            c++;
        if (!before(&q->h[c], &last))
            break;
        q->h[i] = q->h[c];
        i = c;
    }
    if (n)
        q->h[i] = last;
}
