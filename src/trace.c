/* trace.c — placeholder until implemented. */
#include "internal.h"
typedef int amscr__placeholder_trace;
