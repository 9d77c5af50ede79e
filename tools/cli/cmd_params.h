/* cmd_params.h — the shape parameters of a command (library params from the options) and the
 * steps every shape command shares: preparing a shape, reading the scales back. */
#ifndef AMSCR_TOOL_CMD_PARAMS_H
#define AMSCR_TOOL_CMD_PARAMS_H

#include "amscr.h"
#include "cli.h"

/* Builds the params of a command from its options. registration != 0: `register`'s defaults,
 * else the retrieval defaults of search/matrix/eval (see cmd_params.c); given options override
 * both. Returns 0, or an exit code after printing the error. */
int make_params(const opts *o, int registration, amscr_params **out);
/* The params a command uses when no option is given (for the help). 0 or an exit code. */
int default_params(int registration, amscr_params **out);
/* A prepared shape; on failure prints the error naming path and returns -1. */
int prepare(const amscr_params *p, const char *path, const amscr_contour *c, amscr_descriptor **out);
/* The scale values of p in a malloc'ed array of *n; NULL on failure. */
double *params_scales(const amscr_params *p, size_t *n);

#endif
