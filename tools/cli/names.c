/* names.c — the name/value tables of the tool (see names.h). */
#include "names.h"

#include <stdio.h>
#include <string.h>

#include "amscr.h"

#define TABLE(a) {a, sizeof a / sizeof a[0]}

static const tool_name METHODS[] = {
    {"acma", AMSCR_METHOD_ACMA},
    {"amscr", AMSCR_METHOD_AMSCR},
    {"binary-em", AMSCR_METHOD_BINARY_EM},
    {"multiclass-em", AMSCR_METHOD_MULTICLASS_EM},
};
static const tool_name PARAMS[] = {
    {"affine", AMSCR_PARAM_AFFINE},
    {"euclidean", AMSCR_PARAM_EUCLIDEAN},
    {"whitened", AMSCR_PARAM_WHITENED},
};
static const tool_name INVARIANCES[] = {
    {"affine", AMSCR_INVARIANCE_AFFINE},
    {"similarity", AMSCR_INVARIANCE_SIMILARITY},
    {"penalized", AMSCR_INVARIANCE_PENALIZED},
};
static const tool_name PROTOCOLS[] = {
    {"all", PROTO_ALL},
    {"bullseye", PROTO_BULLSEYE},
    {"topk", PROTO_TOPK},
    {"nn", PROTO_NN},
    {"split", PROTO_SPLIT},
    {"groups", PROTO_GROUPS},
};

static const tool_name STAGES[] = {
    {"recovery", 1},
    {"polish", 1},
    {"pixel_grid", 1},
    {"despike", 0},
    {"order", 0},
    {"even_spacing", 0},
};

const name_table METHOD_NAMES = TABLE(METHODS);
const name_table PARAM_NAMES = TABLE(PARAMS);
const name_table INVARIANCE_NAMES = TABLE(INVARIANCES);
const name_table PROTOCOL_NAMES = TABLE(PROTOCOLS);
const name_table STAGE_NAMES = TABLE(STAGES);

int stage_lookup(const char *s)
{
    for (size_t i = 0; i < STAGE_NAMES.n; i++)
        if (strcmp(s, STAGE_NAMES.v[i].name) == 0)
            return STAGE_NAMES.v[i].value;
    return -1;
}

int name_is(const char *s, const char *name)
{
    for (; *s && *name; s++, name++) {
        char a = *s, b = *name;
        if (a >= 'A' && a <= 'Z')
            a = (char)(a - 'A' + 'a');
        if (a == '_')
            a = '-';
        if (a != b)
            return 0;
    }
    return *s == '\0' && *name == '\0';
}

int name_lookup(const name_table *t, const char *s, int *out)
{
    for (size_t i = 0; i < t->n; i++)
        if (name_is(s, t->v[i].name)) {
            *out = t->v[i].value;
            return 0;
        }
    return -1;
}

const char *name_of(const name_table *t, int value)
{
    for (size_t i = 0; i < t->n; i++)
        if (t->v[i].value == value)
            return t->v[i].name;
    return "unknown";
}

/* Joins the names with sep, last before the final one, and " (default)" after dflt's. */
static const char *join(const name_table *t, const char *sep, const char *last, int dflt, char *buf, size_t cap)
{
    size_t len = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < t->n && len < cap; i++) {
        const char *s = i == 0 ? "" : i + 1 == t->n ? last : sep;
        const char *mark = t->v[i].value == dflt ? " (default)" : "";
        int w = snprintf(buf + len, cap - len, "%s%s%s", s, t->v[i].name, mark);
        if (w < 0)
            break;
        len += (size_t)w;
    }
    return buf;
}

const char *name_list(const name_table *t, char *buf, size_t cap) { return join(t, ", ", " or ", -1, buf, cap); }

const char *name_choices(const name_table *t, int dflt, char *buf, size_t cap)
{
    return join(t, " | ", " | ", dflt, buf, cap);
}
