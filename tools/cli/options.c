/* options.c — the options of the amscr tool: one table maps every spelling to an option id
 * and the commands that accept it; set_option switches on the id. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "draw.h"
#include "image.h"
#include "names.h"

typedef enum opt_id {
    O_OUTPUT,
    O_THRESHOLD,
    O_JSON,
    O_OVERLAY,
    O_PLOT,
    O_SHEET,
    O_ALL,
    O_JOIN,
    O_MIN_AREA,
    O_COMPONENT,
    O_ADD,
    O_CANDIDATES,
    O_NAMES,
    O_TOP,
    O_PROTOCOL,
    O_RANKS,
    O_TRAIN,
    O_SPLITS,
    O_SEED,
    O_METHOD,
    O_POINTS,
    O_SCALES,
    O_REFLECTIONS,
    O_NO_REFLECTIONS,
    O_OPEN,
    O_REFINE,
    O_THREADS,
    O_KMAX,
    O_SYMMETRIC,
    O_PARAMETRIZATION,
    O_INVARIANCE,
    O_PARTIAL,
    O_NO_POLISH,
    O_STAGE,
    O_RERANK,
    O_NO_RERANK,
    O_CHANNEL_WEIGHT,
    O_AFFINE_SHARE,
    O_AFFINE_VIEW,
    O_INNER_SHARE,
    O_INNER_CLOSING,
    O_FAST,
    O_PAPER,
    O_PIXEL_CHAIN
} opt_id;

typedef struct optdef {
    const char *name;
    opt_id id;
    int has_arg;
    int cmds; /* C_* bits of the commands that accept it */
    const char *metavar;
} optdef;

static const optdef OPTS[] = {
    {"-o", O_OUTPUT, 1, C_CONTOUR | C_MATRIX | C_INDEX, "FILE"},
    {"--output", O_OUTPUT, 1, C_CONTOUR | C_MATRIX | C_INDEX, "FILE"},
    {"--add", O_ADD, 0, C_INDEX, NULL},
    {"--candidates", O_CANDIDATES, 1, C_SEARCH | C_INDEX, "M"},
    {"--threshold", O_THRESHOLD, 1, C_ALL, "N|auto"},
    {"--json", O_JSON, 0, C_CONTOUR | C_REGISTER | C_SEARCH | C_EVAL, NULL},
    {"--overlay", O_OVERLAY, 1, C_REGISTER, "FILE"},
    {"--plot", O_PLOT, 1, C_REGISTER | C_EVAL, "FILE"},
    {"--sheet", O_SHEET, 1, C_SEARCH, "FILE"},
    {"--all", O_ALL, 0, C_CONTOUR, NULL},
    {"--join", O_JOIN, 0, C_CONTOUR, NULL},
    {"--min-area", O_MIN_AREA, 1, C_CONTOUR | C_REGISTER | C_SEARCH, "A"},
    {"--component", O_COMPONENT, 1, C_REGISTER | C_SEARCH, "N"},
    {"--names", O_NAMES, 1, C_MATRIX, "FILE"},
    {"--top", O_TOP, 1, C_SEARCH, "K"},
    {"--protocol", O_PROTOCOL, 1, C_EVAL, "NAME"},
    {"--ranks", O_RANKS, 1, C_EVAL, "K"},
    {"--topk-ranks", O_RANKS, 1, C_EVAL, "K"},
    {"--train", O_TRAIN, 1, C_EVAL, "K"},
    {"--splits", O_SPLITS, 1, C_EVAL, "R"},
    {"--seed", O_SEED, 1, C_EVAL, "S"},
    {"--method", O_METHOD, 1, C_SHAPES, "NAME"},
    {"--points", O_POINTS, 1, C_SHAPES, "N"},
    {"--scales", O_SCALES, 1, C_SHAPES, "S1,S2,..."},
    {"--reflections", O_REFLECTIONS, 0, C_SHAPES, NULL},
    {"--no-reflections", O_NO_REFLECTIONS, 0, C_SHAPES, NULL},
    {"--open", O_OPEN, 0, C_SHAPES, NULL},
    {"--refine", O_REFINE, 1, C_SHAPES, "N"},
    {"--threads", O_THREADS, 1, C_SHAPES, "N"},
    {"--kmax", O_KMAX, 1, C_SHAPES, "K"},
    {"--symmetric", O_SYMMETRIC, 0, C_SHAPES, NULL},
    {"--parametrization", O_PARAMETRIZATION, 1, C_SHAPES, "NAME"},
    {"--invariance", O_INVARIANCE, 1, C_SHAPES, "NAME"},
    {"--partial", O_PARTIAL, 0, C_REGISTER, NULL},
    {"--no-polish", O_NO_POLISH, 0, C_REGISTER, NULL},
    {"--stage", O_STAGE, 1, C_REGISTER, "NAME=on|off"},
    {"--rerank", O_RERANK, 1, C_RETRIEVAL, "K[,ITER]"},
    {"--no-rerank", O_NO_RERANK, 0, C_RETRIEVAL, NULL},
    {"--channel-weight", O_CHANNEL_WEIGHT, 1, C_RETRIEVAL, "W"},
    {"--affine-share", O_AFFINE_SHARE, 1, C_RETRIEVAL, "S"},
    {"--affine-view", O_AFFINE_VIEW, 1, C_RETRIEVAL, "F"},
    {"--inner-share", O_INNER_SHARE, 1, C_RETRIEVAL, "S"},
    {"--inner-closing", O_INNER_CLOSING, 1, C_RETRIEVAL, "C"},
    {"--fast", O_FAST, 0, C_RETRIEVAL, NULL},
    {"--paper", O_PAPER, 0, C_RETRIEVAL, NULL},
    {"--pixel-chain", O_PIXEL_CHAIN, 0, C_ALL, NULL},
};

void opts_init(opts *o, const tool_command *c)
{
    memset(o, 0, sizeof *o);
    o->cmd = c->name;
    o->cmd_bit = c->bit;
    o->threshold = TOOL_THRESHOLD_UNSET;
    o->reflections = -1;
    o->top = TOOL_TOP_DEFAULT;
    o->protocol_id = PROTO_ALL;
    o->splits = TOOL_SPLITS_DEFAULT;
    o->seed = TOOL_SEED_DEFAULT;
    o->min_area = TOOL_MIN_AREA_DEFAULT;
    o->component = -1;
    o->candidates = TOOL_CANDIDATES_DEFAULT;
}

/* c a decimal digit: an integer option starts with one, since strtoull would skip blanks and
 * take a sign (' -1' wrapped to 2^64 - 1). */
static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static int parse_size(const char *opt, const char *s, size_t lo, size_t hi, size_t *out)
{
    char *end;
    errno = 0;
    if (!is_digit(s[0]))
        return usage_error(opt, "expected an integer %zu..%zu, got '%s'", lo, hi, s);
    unsigned long long v = strtoull(s, &end, 10);
    if (errno != 0 || *end != '\0' || v < lo || v > hi)
        return usage_error(opt, "expected an integer %zu..%zu, got '%s'", lo, hi, s);
    *out = (size_t)v;
    return 0;
}

/* --stage NAME=on|off (repeatable): NAME one of STAGE_NAMES, the stages the help lists (the
 * library checks it again: amscr_params_set_stage). */
static int parse_stage(const char *opt, const char *s, opts *o)
{
    const char *eq = strchr(s, '=');
    size_t len = eq ? (size_t)(eq - s) : 0;
    if (!eq || len == 0 || len >= sizeof o->stage_name[0] || (strcmp(eq + 1, "on") != 0 && strcmp(eq + 1, "off") != 0))
        return usage_error(opt, "expected NAME=on or NAME=off, got '%s'", s);
    if (o->nstages == TOOL_STAGES_MAX)
        return usage_error(opt, "at most %d stages", TOOL_STAGES_MAX);
    memcpy(o->stage_name[o->nstages], s, len);
    o->stage_name[o->nstages][len] = '\0';
    if (stage_lookup(o->stage_name[o->nstages]) < 0) {
        char list[200];
        return usage_error(opt, "'%s' is not a switchable stage (%s)", o->stage_name[o->nstages],
                           name_list(&STAGE_NAMES, list, sizeof list));
    }
    o->stage_on[o->nstages++] = strcmp(eq + 1, "on") == 0;
    return 0;
}

/* parse_size into an unsigned field, setting *set. */
static int parse_unsigned(const char *opt, const char *s, size_t lo, size_t hi, int *set, unsigned *out)
{
    size_t t;
    *set = 1;
    if (parse_size(opt, s, lo, hi, &t) != 0)
        return TOOL_EXIT_USAGE;
    *out = (unsigned)t;
    return 0;
}

static int parse_scales(const char *s, double *out, size_t *n)
{
    size_t k = 0;
    const char *p = s;
    if (*p == '\0')
        return usage_error("--scales", "expected a comma-separated list of numbers, got ''");
    for (;;) {
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || errno != 0 || !isfinite(v) || (*end != ',' && *end != '\0'))
            return usage_error("--scales", "expected a comma-separated list of numbers, got '%s'", s);
        if (k == AMSCR_MAX_SCALES)
            return usage_error("--scales", "at most %u scales", (unsigned)AMSCR_MAX_SCALES);
        out[k++] = v;
        if (*end == '\0')
            break;
        p = end + 1;
    }
    *n = k;
    return 0;
}

static int parse_threshold(const char *opt, const char *v, int *out)
{
    size_t t;
    if (name_is(v, "auto") || name_is(v, "otsu")) {
        *out = AMSCR_THRESHOLD_AUTO;
        return 0;
    }
    if (parse_size(opt, v, 0, TOOL_THRESHOLD_MAX, &t) != 0)
        return TOOL_EXIT_USAGE;
    *out = (int)t;
    return 0;
}

/* K[,ITER] of --rerank. */
static int parse_rerank(const char *opt, const char *v, opts *o)
{
    char *end = NULL;
    unsigned long k = strtoul(v, &end, 10), it = TOOL_RERANK_ITERS;
    int digits = is_digit(v[0]);
    if (end && *end == ',') {
        char *e2 = NULL;
        digits = digits && is_digit(end[1]);
        it = strtoul(end + 1, &e2, 10);
        end = e2;
    }
    if (!end || *end != '\0' || !digits || k < 1 || k > TOOL_RERANK_K_MAX || it < 1 || it > TOOL_RERANK_ITERS_MAX)
        return usage_error(opt, "expected K[,ITER] with 1 <= K <= %d and 1 <= ITER <= %d, got '%s'",
                           TOOL_RERANK_K_MAX, TOOL_RERANK_ITERS_MAX, v);
    o->rerank_set = 1;
    o->rerank_k = (size_t)k;
    o->rerank_iters = (unsigned)it;
    return 0;
}

/* v as a whole finite number into *x: 1, or 0 when v is not one. */
static int whole_number(const char *v, double *x)
{
    char *end = NULL;
    errno = 0;
    *x = strtod(v, &end);
    return end != v && *end == '\0' && errno == 0 && isfinite(*x);
}

/* A fraction 0..1 (--channel-weight, --affine-share, --inner-share, --inner-closing) into *out,
 * setting *set. */
static int parse_fraction(const char *opt, const char *v, int *set, double *out)
{
    double x;
    if (!whole_number(v, &x) || !(x >= 0.0 && x <= 1.0))
        return usage_error(opt, "expected a number 0..1, got '%s'", v);
    *set = 1;
    *out = x;
    return 0;
}

/* --affine-view F: 0, or a factor in [1, 100]. */
static int parse_affine_view(const char *opt, const char *v, opts *o)
{
    double x;
    if (!whole_number(v, &x) || !(x == 0.0 || (x >= 1.0 && x <= 100.0)))
        return usage_error(opt, "expected 0 or a factor in [1, 100], got '%s'", v);
    o->affine_view_set = 1;
    o->affine_view = x;
    return 0;
}

/* --paper: the paper's method exactly as 0.1 computed it (the AMSCR distance alone in the
 * affine group, no refinement, no re-ranking); later options still override. */
static void set_paper(opts *o)
{
    o->channel_weight_set = 1;
    o->channel_weight = 0.0;
    o->rerank_set = 1;
    o->rerank_k = 0;
    o->inv_set = 1;
    o->inv = AMSCR_INVARIANCE_AFFINE;
    o->refine_set = 1;
    o->refine = 0;
}

/* A value of a name table into *out (an enum field), setting *set. */
static int parse_name(const char *opt, const char *v, const name_table *t, int *set, int *out)
{
    char list[200];
    if (set)
        *set = 1;
    if (name_lookup(t, v, out) != 0)
        return usage_error(opt, "expected %s, got '%s'", name_list(t, list, sizeof list), v);
    return 0;
}

static int set_picture(opts *o, opt_id id, const char *v)
{
    if (id == O_OVERLAY || id == O_SHEET) {
        const char *opt = id == O_OVERLAY ? "--overlay" : "--sheet";
        if (!draw_overlay_ext_ok(v))
            return usage_error(opt, "'%s': the picture must be a .png or .svg file", v);
        *(id == O_OVERLAY ? &o->overlay : &o->sheet) = v;
        return 0;
    }
    char ext[16];
    path_ext(v, ext);
    if (strcmp(ext, ".svg") != 0) /* register's and eval's plots */
        return usage_error("--plot", "'%s': the plot is an .svg file", v);
    o->plot = v;
    return 0;
}

/* Applies option d (value v, NULL for a flag). Errors name the option as typed. */
static int set_option(opts *o, const optdef *d, const char *v)
{
    const char *n = d->name;
    int e = 0, r;
    switch (d->id) {
    case O_OUTPUT:
    case O_NAMES:
        if (v[0] == '\0')
            return usage_error(n, "expected a file name, got ''");
        *(d->id == O_OUTPUT ? &o->out : &o->names) = v;
        return 0;
    case O_THRESHOLD: return parse_threshold(n, v, &o->threshold);
    case O_JSON: o->json = 1; return 0;
    case O_OVERLAY:
    case O_SHEET:
    case O_PLOT: return set_picture(o, d->id, v);
    case O_TOP: return parse_size(n, v, 1, TOOL_TOP_MAX, &o->top) != 0 ? TOOL_EXIT_USAGE : 0;
    case O_PROTOCOL:
        o->protocol = v;
        return parse_name(n, v, &PROTOCOL_NAMES, NULL, &o->protocol_id);
    case O_RANKS: return parse_size(n, v, 1, TOOL_RANKS_MAX, &o->ranks) != 0 ? TOOL_EXIT_USAGE : 0;
    case O_TRAIN: return parse_size(n, v, 1, TOOL_TOP_MAX, &o->train) != 0 ? TOOL_EXIT_USAGE : 0;
    case O_SPLITS: return parse_size(n, v, 1, TOOL_SPLITS_MAX, &o->splits) != 0 ? TOOL_EXIT_USAGE : 0;
    case O_SEED: {
        size_t sd;
        if (parse_size(n, v, 0, SIZE_MAX, &sd) != 0)
            return TOOL_EXIT_USAGE;
        o->seed = sd;
        return 0;
    }
    case O_ALL: o->all = 1; return 0;
    case O_JOIN: o->join = 1; return 0;
    case O_ADD: o->add = 1; return 0;
    case O_CANDIDATES:
        o->candidates_set = 1;
        return parse_size(n, v, 0, TOOL_TOP_MAX, &o->candidates) != 0 ? TOOL_EXIT_USAGE : 0;
    case O_MIN_AREA: {
        char *end;
        errno = 0;
        double a = strtod(v, &end);
        if (end == v || *end != '\0' || errno != 0 || !(a >= 0.0) || !isfinite(a))
            return usage_error(n, "expected an area >= 0 in pixels^2, got '%s'", v);
        o->min_area = a;
        o->min_area_set = 1;
        return 0;
    }
    case O_COMPONENT: {
        size_t k;
        if (parse_size(n, v, 0, 100000000, &k) != 0)
            return TOOL_EXIT_USAGE;
        o->component = (long)k;
        return 0;
    }
    case O_METHOD:
        r = parse_name(n, v, &METHOD_NAMES, &o->method_set, &e);
        o->method = (amscr_method)e;
        return r;
    case O_POINTS:
        o->points_set = 1;
        return parse_size(n, v, TOOL_POINTS_MIN, AMSCR_MAX_SAMPLES, &o->points) != 0 ? TOOL_EXIT_USAGE : 0;
    case O_SCALES:
        o->scales_set = 1;
        return parse_scales(v, o->scales, &o->nscales) != 0 ? TOOL_EXIT_USAGE : 0;
    case O_REFLECTIONS: o->reflections = 1; return 0;
    case O_NO_REFLECTIONS: o->reflections = 0; return 0;
    case O_OPEN: o->open = 1; return 0;
    case O_PARTIAL: o->partial = 1; return 0;
    case O_NO_POLISH: o->no_polish = 1; return 0;
    case O_STAGE: return parse_stage(n, v, o);
    case O_REFINE: return parse_unsigned(n, v, 0, TOOL_REFINE_MAX, &o->refine_set, &o->refine);
    case O_THREADS: return parse_unsigned(n, v, 0, TOOL_THREADS_MAX, &o->threads_set, &o->threads);
    case O_KMAX: return parse_unsigned(n, v, 1, TOOL_KMAX_MAX, &o->kmax_set, &o->kmax);
    case O_SYMMETRIC: o->symmetric = 1; return 0;
    case O_PARAMETRIZATION:
        r = parse_name(n, v, &PARAM_NAMES, &o->param_set, &e);
        o->param = (amscr_parametrization)e;
        return r;
    case O_INVARIANCE:
        r = parse_name(n, v, &INVARIANCE_NAMES, &o->inv_set, &e);
        o->inv = (amscr_invariance)e;
        return r;
    case O_RERANK: return parse_rerank(n, v, o);
    case O_NO_RERANK:
        o->rerank_set = 1;
        o->rerank_k = 0;
        return 0;
    case O_CHANNEL_WEIGHT: return parse_fraction(n, v, &o->channel_weight_set, &o->channel_weight);
    case O_AFFINE_SHARE: return parse_fraction(n, v, &o->affine_share_set, &o->affine_share);
    case O_AFFINE_VIEW: return parse_affine_view(n, v, o);
    case O_INNER_SHARE: return parse_fraction(n, v, &o->inner_share_set, &o->inner_share);
    case O_INNER_CLOSING: return parse_fraction(n, v, &o->inner_closing_set, &o->inner_closing);
    case O_FAST:
        o->affine_share_set = 1;
        o->affine_share = 0.0;
        return 0;
    case O_PAPER: set_paper(o); return 0;
    case O_PIXEL_CHAIN: image_set_trace_flags(AMSCR_TRACE_PIXEL_CHAIN); return 0;
    }
    return 0;
}

/* The option named by argument a (up to '=' for a long option), or NULL. */
static const optdef *find_option(const char *a, size_t nl)
{
    for (size_t k = 0; k < sizeof OPTS / sizeof OPTS[0]; k++)
        if (strlen(OPTS[k].name) == nl && strncmp(OPTS[k].name, a, nl) == 0)
            return &OPTS[k];
    return NULL;
}

/* One option argument argv[*i] (advanced past a separate value). */
static int parse_option(opts *o, int argc, char **argv, int *i)
{
    const char *a = argv[*i];
    const char *eq = strchr(a, '=');
    int inline_value = eq && a[1] == '-'; /* --name=value */
    size_t nl = inline_value ? (size_t)(eq - a) : strlen(a);
    const optdef *d = find_option(a, nl);
    if (d == NULL || !(d->cmds & o->cmd_bit))
        return usage_error(o->cmd, "unknown option '%.*s' (see 'amscr %s --help')", (int)nl, a, o->cmd);
    const char *v = NULL;
    if (d->has_arg) {
        if (inline_value) {
            v = eq + 1;
        } else {
            if (*i + 1 >= argc)
                return usage_error(o->cmd, "option '%s' needs a value (%s)", d->name, d->metavar);
            v = argv[++*i];
        }
    } else if (inline_value) {
        return usage_error(o->cmd, "option '%s' takes no value", d->name);
    }
    return set_option(o, d, v);
}

int parse_args(opts *o, const tool_command *c, int argc, char **argv)
{
    int only_pos = 0;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (!only_pos && strcmp(a, "--") == 0) {
            only_pos = 1;
            continue;
        }
        if (!only_pos && a[0] == '-' && a[1] != '\0') {
            if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0)
                return -1;
            if (strncmp(a, "--help=", 7) == 0)
                return usage_error(o->cmd, "option '--help' takes no value");
            int r = parse_option(o, argc, argv, &i);
            if (r != 0)
                return r;
            continue;
        }
        if (o->npos >= c->npos)
            return usage_error(o->cmd, "unexpected argument '%s' (usage: amscr %s %s)", a, o->cmd, c->args);
        if (a[0] == '\0') /* every argument names a file */
            return usage_error(o->cmd, "empty file name (usage: amscr %s %s)", o->cmd, c->args);
        o->pos[o->npos++] = a;
    }
    if (o->npos < c->npos)
        return usage_error(o->cmd, "missing argument (usage: amscr %s %s)", o->cmd, c->args);
    if (o->min_area_set && !o->all && o->component < 0) /* it filters the contours of those two */
        return usage_error("--min-area", "only with %s", strcmp(o->cmd, "contour") == 0 ? "--all" : "--component");
    return 0;
}
