/* stage_names.c — the names of amscr_register's stages in pipeline order (AMSCR__STAGE_*) and which
 * of them amscr_params_set_stage switches. The stage table (register/stages.c) attaches each
 * stage's function and condition to these indices; the names live here so that the params object
 * knows its switches without the layer above. */
#include "internal.h"

#include <string.h>

static const struct {
    const char *name;
    int optional; /* switchable by amscr_params_set_stage */
} NAMES[AMSCR__NUM_STAGES] = {
    [AMSCR__STAGE_DESPIKE] = {"despike", 1},
    [AMSCR__STAGE_SEARCH] = {"search", 0},
    [AMSCR__STAGE_METHOD] = {"method", 0},
    [AMSCR__STAGE_RECOVERY] = {"recovery", 1},
    [AMSCR__STAGE_FINAL_SOLVE] = {"final_solve", 0},
    [AMSCR__STAGE_SYMMETRIC] = {"symmetric", 0},
    [AMSCR__STAGE_POLISH] = {"polish", 1},
    [AMSCR__STAGE_ORDER] = {"order", 1},
    [AMSCR__STAGE_EVEN] = {"even_spacing", 1},
    [AMSCR__STAGE_ALTERNATIVES] = {"alternatives", 0},
    [AMSCR__STAGE_CORRESPOND] = {"correspondences", 0},
    [AMSCR__STAGE_PIXEL_GRID] = {"pixel_grid", 1},
};

const char *amscr__stage_name(size_t i) { return i < AMSCR__NUM_STAGES ? NAMES[i].name : NULL; }

int amscr__stage_switch(const char *name)
{
    for (int i = 0; name && i < AMSCR__NUM_STAGES; i++)
        if (NAMES[i].optional && strcmp(NAMES[i].name, name) == 0)
            return i;
    return -1;
}
