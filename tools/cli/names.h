/* names.h — the tool's name/value tables (method, parametrization, invariance, eval protocol):
 * one table per enum, read by the option parser, by the error messages that list the accepted
 * names, by the help text and by the printed results, so they cannot disagree. */
#ifndef AMSCR_TOOL_NAMES_H
#define AMSCR_TOOL_NAMES_H

#include <stddef.h>

typedef struct tool_name {
    const char *name;
    int value;
} tool_name;

typedef struct name_table {
    const tool_name *v;
    size_t n;
} name_table;

/* Evaluation protocols of `amscr eval`. */
enum { PROTO_ALL, PROTO_BULLSEYE, PROTO_TOPK, PROTO_NN, PROTO_SPLIT, PROTO_GROUPS };

extern const name_table METHOD_NAMES;     /* amscr_method */
extern const name_table PARAM_NAMES;      /* amscr_parametrization */
extern const name_table INVARIANCE_NAMES; /* amscr_invariance */
extern const name_table PROTOCOL_NAMES;   /* PROTO_* */
/* The stages of amscr_register that --stage switches (amscr_params_set_stage), each with 1 when
 * it is on by default; named exactly (stage_lookup), as the library names them. */
extern const name_table STAGE_NAMES;

/* Case-insensitive match in which '_' equals '-' ("Binary_EM" is binary-em). */
int name_is(const char *s, const char *name);
/* The value named s (name_is); -1 when none. */
int name_lookup(const name_table *t, const char *s, int *out);
/* The name of a value; "unknown" when none. */
const char *name_of(const name_table *t, int value);
/* The stage named exactly s: its on-by-default flag (STAGE_NAMES), -1 when none. */
int stage_lookup(const char *s);
/* The names joined for an error message: "a, b or c". */
const char *name_list(const name_table *t, char *buf, size_t cap);
/* The names joined for a help line, " (default)" after the one of value dflt (none when
 * dflt is no value of the table): "a | b (default) | c". */
const char *name_choices(const name_table *t, int dflt, char *buf, size_t cap);

#endif
