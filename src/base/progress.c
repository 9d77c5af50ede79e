/* progress.c — a call made of stages reports each stage's progress as its share of the whole
 * (the amscr_progress_fn contract: done / total is the fraction, monotone over the call). */
#include "internal.h"

int amscr__stage_cb(void *user, size_t done, size_t total)
{
    amscr__stages *sp = user;
    return sp->fn(sp->user, sp->stage * total + done, total * sp->stages);
}
