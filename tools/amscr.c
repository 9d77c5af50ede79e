/* amscr.c — the amscr command-line tool (DESIGN.md §6). Uses the public API only
 * (STYLE.md rule 25): no src/ internals.
 *
 *   amscr contour IMG [-o FILE]
 *   amscr register SRC TGT [--json] [--overlay FILE] [--plot FILE] [shape options]
 *   amscr search QUERY COLLECTION [--top K] [--json]
 *   amscr matrix COLLECTION -o FILE.tsv|FILE.npy
 *   amscr eval COLLECTION [--protocol all|bullseye|topk|nn] [--ranks K] [--json]
 *
 * Exit codes: 0 success, 1 bad input or failure (one line on stderr naming the file),
 * 2 usage error. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amscr.h"
#include "collection.h"
#include "draw.h"
#include "image.h"
#include "util.h"

/* ================================================================ options */
enum {
    C_CONTOUR = 1,
    C_REGISTER = 2,
    C_SEARCH = 4,
    C_MATRIX = 8,
    C_EVAL = 16,
    C_SHAPES = C_REGISTER | C_SEARCH | C_MATRIX | C_EVAL,
    C_ALL = 31
};

typedef struct opts {
    const char *cmd;
    int cmd_bit;
    const char *pos[4];
    int npos;
    const char *out;
    int threshold;
    int json;
    const char *overlay;
    const char *plot;
    const char *names;
    size_t top;
    const char *protocol;
    size_t ranks;
    /* shape parameters (set only when given) */
    int method_set;
    amscr_method method;
    int points_set;
    size_t points;
    int scales_set;
    double scales[AMSCR_MAX_SCALES];
    size_t nscales;
    int reflections; /* -1: the command's default */
    int open;
    int refine_set;
    unsigned refine;
    int threads_set;
    unsigned threads;
    int kmax_set;
    unsigned kmax;
    int symmetric;
    int param_set;
    amscr_parametrization param;
    int inv_set;
    amscr_invariance inv;
    size_t rerank_k;         /* 0: no contextual re-ranking */
    unsigned rerank_iters;
} opts;

typedef struct optdef {
    const char *name;
    int has_arg;
    int cmds;
    const char *metavar;
} optdef;

static const optdef OPTS[] = {
    {"-o", 1, C_CONTOUR | C_MATRIX, "FILE"},
    {"--output", 1, C_CONTOUR | C_MATRIX, "FILE"},
    {"--threshold", 1, C_ALL, "N|auto"},
    {"--json", 0, C_REGISTER | C_SEARCH | C_EVAL, NULL},
    {"--overlay", 1, C_REGISTER, "FILE"},
    {"--plot", 1, C_REGISTER, "FILE"},
    {"--names", 1, C_MATRIX, "FILE"},
    {"--top", 1, C_SEARCH, "K"},
    {"--protocol", 1, C_EVAL, "NAME"},
    {"--ranks", 1, C_EVAL, "K"},
    {"--topk-ranks", 1, C_EVAL, "K"},
    {"--method", 1, C_SHAPES, "NAME"},
    {"--points", 1, C_SHAPES, "N"},
    {"--scales", 1, C_SHAPES, "S1,S2,..."},
    {"--reflections", 0, C_SHAPES, NULL},
    {"--no-reflections", 0, C_SHAPES, NULL},
    {"--open", 0, C_SHAPES, NULL},
    {"--refine", 1, C_SHAPES, "N"},
    {"--threads", 1, C_SHAPES, "N"},
    {"--kmax", 1, C_SHAPES, "K"},
    {"--symmetric", 0, C_SHAPES, NULL},
    {"--parametrization", 1, C_SHAPES, "NAME"},
    {"--invariance", 1, C_SHAPES, "NAME"},
    {"--rerank", 1, C_SEARCH | C_MATRIX | C_EVAL, "K[,ITER]"},
    {"--no-rerank", 0, C_SEARCH | C_MATRIX | C_EVAL, NULL},
};

static const char *HELP_MAIN =
    "usage: amscr COMMAND [options] ...\n"
    "\n"
    "Affine multi-scale curve registration (AMSCR) of 2-D shapes.\n"
    "\n"
    "commands:\n"
    "  contour IMG [-o FILE]             trace the outer contour of a silhouette image\n"
    "  register SRC TGT                  register SRC onto TGT: affine map, distance, scales\n"
    "  search QUERY COLLECTION           the shapes of a collection closest to QUERY\n"
    "  matrix COLLECTION -o FILE         all-pairs distance matrix (.tsv or .npy)\n"
    "  eval COLLECTION                   retrieval scores: bull's eye, top-k table, 1-NN\n"
    "\n"
    "  amscr --version                   print the library version\n"
    "  amscr COMMAND --help              options of a command\n"
    "\n"
    "Shapes are PNG or PGM silhouettes (detected by their magic bytes) or text point\n"
    "lists (one \"x y\" or \"x,y\" per line, '#' comments). A COLLECTION is a folder of\n"
    "shapes or a manifest.tsv with 'file' and 'class' columns.\n"
    "Exit status: 0 success, 1 bad input or failure, 2 usage error.\n";

static const char *HELP_SHAPE_OPTS =
    "image options:\n"
    "  --threshold N|auto      pixels > N are 'on' (0..254, default 127); auto = Otsu.\n"
    "                          Polarity is automatic: the image border is background.\n"
    "shape options:\n"
    "  --method NAME           acma | amscr | binary-em | multiclass-em (default)\n"
    "  --points N              samples per curve (default 256 for register, 128 otherwise)\n"
    "  --scales S1,S2,...      smoothing scales in samples (default: the library's)\n"
    "  --reflections           also try mirror matches (default: off for register,\n"
    "  --no-reflections          on for search, matrix and eval)\n"
    "  --open                  open curves (default closed)\n"
    "  --refine N              refinement iterations in the aligned frame (0..50; default:\n"
    "                          20 for register, 2 for search/matrix/eval; 0 is fastest)\n"
    "  --kmax K                largest K of the elbow (1..16)\n"
    "  --symmetric             average the distance over both directions\n"
    "  --parametrization NAME  affine (default) | euclidean | whitened\n"
    "  --invariance NAME       affine | similarity | penalized (default: affine for register,\n"
    "                          similarity for search/matrix/eval)\n"
    "  --rerank K[,ITER]       (search/matrix/eval) contextual re-ranking: diffusion on the\n"
    "                          K-nearest-neighbour graph, ITER iterations (default 5,20);\n"
    "  --no-rerank             the plain pairwise distances\n"
    "  --threads N             threads for batch work (0 = all cores, the default)\n";

static void print_cmd_help(const char *cmd)
{
    if (strcmp(cmd, "contour") == 0) {
        printf("usage: amscr contour IMG [-o FILE] [--threshold N|auto]\n"
               "\n"
               "Traces the outer boundary of the largest 8-connected foreground component of a\n"
               "PNG or PGM silhouette (holes and specks are ignored) and prints its points, one\n"
               "\"x y\" per line (x = column, y = row, pixel centres), counter-clockwise in a y-up\n"
               "frame. A text point list is passed through. -o writes to FILE (atomically).\n"
               "\n"
               "Images are converted to 8-bit luminance (RGB: Rec. 601 weights; 16-bit scaled).\n"
               "With transparency, transparent pixels (alpha < 128) are background: a uniformly\n"
               "coloured image on a transparent background is traced by its alpha channel.\n"
               "\n"
               "  -o, --output FILE       write the points to FILE instead of stdout\n"
               "  --threshold N|auto      pixels > N are 'on' (0..254, default 127); auto = Otsu\n");
    } else if (strcmp(cmd, "register") == 0) {
        printf("usage: amscr register SRC TGT [options]\n"
               "\n"
               "Registers the source shape SRC onto the target TGT: the affine map (A, B) with\n"
               "TGT ~ A SRC + B in input coordinates, the affine-invariant distance, the residual\n"
               "of every scale, the scales kept by the selection, the start shift and whether a\n"
               "mirror match was used. Reflections are off by default here.\n"
               "\n"
               "  --json                  print one JSON object (keys A, B, distance, method,\n"
               "                          scales, residuals, kept, shift, reflected, k,\n"
               "                          threshold, sse, mixture, ...)\n"
               "  --overlay FILE          picture (.png or .svg): target, source before and after\n"
               "  --plot FILE             SVG: residual per scale with the Bayes threshold and the\n"
               "                          kept scales, and the elbow curve SSE(K)\n"
               "\n%s",
               HELP_SHAPE_OPTS);
    } else if (strcmp(cmd, "search") == 0) {
        printf("usage: amscr search QUERY COLLECTION [--top K] [--json] [options]\n"
               "\n"
               "Ranks the shapes of COLLECTION (a folder or a manifest.tsv) by their distance\n"
               "from QUERY and prints the K closest (default 10). Reflections are on by default.\n"
               "\n"
               "  --top K                 how many results (default 10)\n"
               "  --json                  print one JSON object\n"
               "\n%s",
               HELP_SHAPE_OPTS);
    } else if (strcmp(cmd, "matrix") == 0) {
        printf("usage: amscr matrix COLLECTION -o FILE [--names FILE] [options]\n"
               "\n"
               "Computes the n x n matrix D[i][j] = distance(shape i -> shape j) of a collection\n"
               "(rows in collection order: folder files sorted by name, or manifest order).\n"
               "FILE ending in .npy: NumPy .npy v1.0, little-endian float64, C order;\n"
               "otherwise (.tsv, or - for stdout): tab-separated text, one row per line, after a\n"
               "'#' comment line listing the files. Reflections are on by default.\n"
               "\n"
               "  -o, --output FILE       the matrix file (.tsv, .npy or -)\n"
               "  --names FILE            also write the row order: 'file<TAB>class' lines\n"
               "\n%s",
               HELP_SHAPE_OPTS);
    } else if (strcmp(cmd, "eval") == 0) {
        printf("usage: amscr eval COLLECTION [--protocol P] [--ranks K] [--json] [options]\n"
               "\n"
               "Retrieval scores of a labelled collection from its full distance matrix:\n"
               "  bullseye  bull's eye (MPEG-7): same-class shapes among the 2*Nc nearest,\n"
               "            query included, divided by the sum of class sizes\n"
               "  topk      for rank r = 1..K, how many queries have a same-class r-th nearest\n"
               "            neighbour (query excluded; Kimia tables)\n"
               "  nn        leave-one-out nearest-neighbour accuracy\n"
               "  all       all three (default)\n"
               "Classes: a folder's file names (\"bird-3.png\" -> bird) or the manifest's column.\n"
               "Reflections are on by default.\n"
               "\n"
               "  --protocol P            all | bullseye | topk | nn\n"
               "  --ranks K               ranks of the top-k table (default 10; Kimia-216 uses 11;\n"
               "                          alias --topk-ranks)\n"
               "  --json                  one JSON object: n, classes, seconds and bullseye,\n"
               "                          topk, nn_accuracy (those the protocol computes)\n"
               "\n%s",
               HELP_SHAPE_OPTS);
    }
}

static int usage_error(const char *what, const char *fmt, ...) TOOL_PRINTF(2, 3);
static int usage_error(const char *what, const char *fmt, ...)
{
    char msg[600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    tool_error(what, "%s", msg);
    return TOOL_EXIT_USAGE;
}

static int parse_size(const char *opt, const char *s, size_t lo, size_t hi, size_t *out)
{
    char *end;
    errno = 0;
    if (s[0] == '-' || s[0] == '\0')
        return usage_error(opt, "expected an integer %zu..%zu, got '%s'", lo, hi, s);
    unsigned long long v = strtoull(s, &end, 10);
    if (errno != 0 || *end != '\0' || v < lo || v > hi)
        return usage_error(opt, "expected an integer %zu..%zu, got '%s'", lo, hi, s);
    *out = (size_t)v;
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

static const char *method_name(amscr_method m)
{
    switch (m) {
    case AMSCR_METHOD_ACMA: return "acma";
    case AMSCR_METHOD_AMSCR: return "amscr";
    case AMSCR_METHOD_BINARY_EM: return "binary-em";
    case AMSCR_METHOD_MULTICLASS_EM: return "multiclass-em";
    }
    return "unknown";
}

static int name_is(const char *s, const char *name)
{
    /* case-insensitive, '_' == '-' */
    for (; *s && *name; s++, name++) {
        char a = *s, b = *name;
        if (a >= 'A' && a <= 'Z') a = (char)(a - 'A' + 'a');
        if (a == '_') a = '-';
        if (a != b)
            return 0;
    }
    return *s == '\0' && *name == '\0';
}

static int set_option(opts *o, const optdef *d, const char *v)
{
    const char *n = d->name;
    if (strcmp(n, "-o") == 0 || strcmp(n, "--output") == 0) {
        o->out = v;
    } else if (strcmp(n, "--threshold") == 0) {
        size_t t;
        if (name_is(v, "auto") || name_is(v, "otsu")) {
            o->threshold = AMSCR_THRESHOLD_AUTO;
        } else {
            if (parse_size(n, v, 0, 254, &t) != 0)
                return TOOL_EXIT_USAGE;
            o->threshold = (int)t;
        }
    } else if (strcmp(n, "--json") == 0) {
        o->json = 1;
    } else if (strcmp(n, "--overlay") == 0) {
        if (!draw_overlay_ext_ok(v))
            return usage_error("--overlay", "'%s': the picture must be a .png or .svg file", v);
        o->overlay = v;
    } else if (strcmp(n, "--plot") == 0) {
        char ext[16];
        path_ext(v, ext);
        if (strcmp(ext, ".svg") != 0)
            return usage_error("--plot", "'%s': the plot is an .svg file", v);
        o->plot = v;
    } else if (strcmp(n, "--names") == 0) {
        o->names = v;
    } else if (strcmp(n, "--rerank") == 0) {
        char *end = NULL;
        unsigned long k = strtoul(v, &end, 10), it = 20;
        if (end && *end == ',') {
            char *e2 = NULL;
            it = strtoul(end + 1, &e2, 10);
            end = e2;
        }
        if (!end || *end != '\0' || k < 1 || k > 100000 || it < 1 || it > 1000 || v[0] == '-')
            return usage_error(n, "expected K[,ITER] with K >= 1 and 1 <= ITER <= 1000, got '%s'", v);
        o->rerank_k = (size_t)k;
        o->rerank_iters = (unsigned)it;
    } else if (strcmp(n, "--no-rerank") == 0) {
        o->rerank_k = 0;
    } else if (strcmp(n, "--top") == 0) {
        if (parse_size(n, v, 1, 1000000000, &o->top) != 0)
            return TOOL_EXIT_USAGE;
    } else if (strcmp(n, "--protocol") == 0) {
        if (!(name_is(v, "all") || name_is(v, "bullseye") || name_is(v, "topk") || name_is(v, "nn")))
            return usage_error(n, "expected all, bullseye, topk or nn, got '%s'", v);
        o->protocol = v;
    } else if (strcmp(n, "--ranks") == 0 || strcmp(n, "--topk-ranks") == 0) {
        if (parse_size(n, v, 1, 1000000, &o->ranks) != 0)
            return TOOL_EXIT_USAGE;
    } else if (strcmp(n, "--method") == 0) {
        o->method_set = 1;
        if (name_is(v, "acma"))
            o->method = AMSCR_METHOD_ACMA;
        else if (name_is(v, "amscr"))
            o->method = AMSCR_METHOD_AMSCR;
        else if (name_is(v, "binary-em"))
            o->method = AMSCR_METHOD_BINARY_EM;
        else if (name_is(v, "multiclass-em"))
            o->method = AMSCR_METHOD_MULTICLASS_EM;
        else
            return usage_error(n, "expected acma, amscr, binary-em or multiclass-em, got '%s'", v);
    } else if (strcmp(n, "--points") == 0) {
        o->points_set = 1;
        if (parse_size(n, v, 16, AMSCR_MAX_SAMPLES, &o->points) != 0)
            return TOOL_EXIT_USAGE;
    } else if (strcmp(n, "--scales") == 0) {
        o->scales_set = 1;
        if (parse_scales(v, o->scales, &o->nscales) != 0)
            return TOOL_EXIT_USAGE;
    } else if (strcmp(n, "--reflections") == 0) {
        o->reflections = 1;
    } else if (strcmp(n, "--no-reflections") == 0) {
        o->reflections = 0;
    } else if (strcmp(n, "--open") == 0) {
        o->open = 1;
    } else if (strcmp(n, "--refine") == 0) {
        size_t t;
        o->refine_set = 1;
        if (parse_size(n, v, 0, 50, &t) != 0)
            return TOOL_EXIT_USAGE;
        o->refine = (unsigned)t;
    } else if (strcmp(n, "--threads") == 0) {
        size_t t;
        o->threads_set = 1;
        if (parse_size(n, v, 0, 1024, &t) != 0)
            return TOOL_EXIT_USAGE;
        o->threads = (unsigned)t;
    } else if (strcmp(n, "--kmax") == 0) {
        size_t t;
        o->kmax_set = 1;
        if (parse_size(n, v, 1, 16, &t) != 0)
            return TOOL_EXIT_USAGE;
        o->kmax = (unsigned)t;
    } else if (strcmp(n, "--symmetric") == 0) {
        o->symmetric = 1;
    } else if (strcmp(n, "--parametrization") == 0) {
        o->param_set = 1;
        if (name_is(v, "affine"))
            o->param = AMSCR_PARAM_AFFINE;
        else if (name_is(v, "euclidean"))
            o->param = AMSCR_PARAM_EUCLIDEAN;
        else if (name_is(v, "whitened"))
            o->param = AMSCR_PARAM_WHITENED;
        else
            return usage_error(n, "expected affine, euclidean or whitened, got '%s'", v);
    } else if (strcmp(n, "--invariance") == 0) {
        o->inv_set = 1;
        if (name_is(v, "affine"))
            o->inv = AMSCR_INVARIANCE_AFFINE;
        else if (name_is(v, "similarity"))
            o->inv = AMSCR_INVARIANCE_SIMILARITY;
        else if (name_is(v, "penalized"))
            o->inv = AMSCR_INVARIANCE_PENALIZED;
        else
            return usage_error(n, "expected affine, similarity or penalized, got '%s'", v);
    }
    return 0;
}

/* Parses argv[2..] of a command. Returns 0, TOOL_EXIT_USAGE, or -1 when help was printed. */
static int parse_args(opts *o, int argc, char **argv, int minpos, int maxpos, const char *posnames)
{
    int only_pos = 0;
    for (int i = 2; i < argc; i++) {
        const char *a = argv[i];
        if (!only_pos && strcmp(a, "--") == 0) {
            only_pos = 1;
            continue;
        }
        if (!only_pos && a[0] == '-' && a[1] != '\0') {
            if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
                print_cmd_help(o->cmd);
                return -1;
            }
            const char *eq = strchr(a, '=');
            size_t nl = eq && a[1] == '-' ? (size_t)(eq - a) : strlen(a);
            const optdef *d = NULL;
            for (size_t k = 0; k < sizeof OPTS / sizeof OPTS[0]; k++)
                if (strlen(OPTS[k].name) == nl && strncmp(OPTS[k].name, a, nl) == 0)
                    d = &OPTS[k];
            if (d == NULL || !(d->cmds & o->cmd_bit))
                return usage_error(o->cmd, "unknown option '%.*s' (see 'amscr %s --help')", (int)nl, a, o->cmd);
            const char *v = NULL;
            if (d->has_arg) {
                if (eq && a[1] == '-') {
                    v = eq + 1;
                } else {
                    if (i + 1 >= argc)
                        return usage_error(o->cmd, "option '%s' needs a value (%s)", d->name, d->metavar);
                    v = argv[++i];
                }
            } else if (eq && a[1] == '-') {
                return usage_error(o->cmd, "option '%s' takes no value", d->name);
            }
            int r = set_option(o, d, v);
            if (r != 0)
                return r;
            continue;
        }
        if (o->npos >= maxpos)
            return usage_error(o->cmd, "unexpected argument '%s' (usage: amscr %s %s)", a, o->cmd, posnames);
        o->pos[o->npos++] = a;
    }
    if (o->npos < minpos)
        return usage_error(o->cmd, "missing argument (usage: amscr %s %s)", o->cmd, posnames);
    return 0;
}

/* Builds the params from the options. `registration` selects the command's defaults: register
 * starts from the library's registration preset (N 256, 20 refinement iterations: measured in
 * the README) and does not try mirror images; retrieval starts from the collection defaults
 * (N 128, no refinement: speed) and tries mirror images; flags override both. */
static int make_params(const opts *o, int registration, amscr_params **out)
{
    amscr_params *p = NULL;
    amscr_status st = registration ? amscr_params_new_registration(&p) : amscr_params_new(&p);
    int default_reflections = !registration;
    /* retrieval compares shapes that are rarely affine-distorted copies: the similarity group
     * keeps aspect and shear that tell classes apart (README: retrieval table); registration
     * keeps the full affine group. --invariance overrides. */
    if (st == AMSCR_OK && !registration && !o->inv_set)
        st = amscr_params_set_invariance(p, AMSCR_INVARIANCE_SIMILARITY);
    /* and two refinement iterations: with them the Kimia-99/216 tables meet the paper's rows
     * (985/990, 2355/2376) at ~15x the time of --refine 0 (911, 2358) */
    if (st == AMSCR_OK && !registration && !o->refine_set)
        st = amscr_params_set_refine(p, 2);
    if (st != AMSCR_OK) {
        tool_lib_error(NULL, st);
        return TOOL_EXIT_FAIL;
    }
    const char *opt = NULL;
#define SET(flag, name, call)                                                                                \
    do {                                                                                                     \
        if (st == AMSCR_OK && (flag)) {                                                                      \
            opt = name;                                                                                      \
            st = call;                                                                                       \
        }                                                                                                    \
    } while (0)
    SET(o->points_set, "--points", amscr_params_set_num_samples(p, o->points));
    SET(o->scales_set, "--scales", amscr_params_set_scales(p, o->scales, o->nscales));
    SET(o->method_set, "--method", amscr_params_set_method(p, o->method));
    SET(1, "--reflections", amscr_params_set_reflections(p, o->reflections < 0 ? default_reflections : o->reflections));
    SET(o->open, "--open", amscr_params_set_closed(p, 0));
    SET(o->refine_set, "--refine", amscr_params_set_refine(p, o->refine));
    SET(o->threads_set, "--threads", amscr_params_set_num_threads(p, o->threads));
    SET(o->kmax_set, "--kmax", amscr_params_set_kmax(p, o->kmax));
    SET(o->symmetric, "--symmetric", amscr_params_set_symmetric(p, 1));
    SET(o->param_set, "--parametrization", amscr_params_set_parametrization(p, o->param));
    SET(o->inv_set, "--invariance", amscr_params_set_invariance(p, o->inv));
#undef SET
    if (st != AMSCR_OK) {
        const char *d = lib_detail();
        if (st == AMSCR_E_INVALID_ARG) {
            usage_error(opt, "%s", d[0] ? d : amscr_strerror(st));
            amscr_params_free(p);
            return TOOL_EXIT_USAGE;
        }
        tool_lib_error(opt, st);
        amscr_params_free(p);
        return TOOL_EXIT_FAIL;
    }
    *out = p;
    return 0;
}

/* Scale values of params (p values into a malloc'ed array). */
static double *params_scales(const amscr_params *p, size_t *n)
{
    size_t k = 0;
    if (amscr_params_get_scales(p, NULL, &k) != AMSCR_OK)
        return NULL;
    double *s = xmalloc_array(k ? k : 1, sizeof(double));
    if (s && amscr_params_get_scales(p, s, &k) != AMSCR_OK) {
        free(s);
        return NULL;
    }
    *n = k;
    return s;
}

/* ================================================================ contour */
static int write_points(FILE *fp, const amscr_contour *c)
{
    const double *xy = amscr_contour_xy(c);
    size_t n = amscr_contour_size(c);
    for (size_t i = 0; i < n; i++)
        if (fprintf(fp, "%.17g %.17g\n", xy[2 * i], xy[2 * i + 1]) < 0)
            return -1;
    return 0;
}

static int cmd_contour(opts *o)
{
    amscr_contour *c = NULL;
    if (shape_load(o->pos[0], o->threshold, &c) != 0)
        return TOOL_EXIT_FAIL;
    tool_out out;
    if (tool_out_open(&out, o->out ? o->out : "-") != 0) {
        amscr_contour_free(c);
        return TOOL_EXIT_FAIL;
    }
    if (write_points(out.fp, c) != 0) {
        tool_error(o->out ? o->out : "<stdout>", "write error: %s", strerror(errno));
        tool_out_abort(&out);
        amscr_contour_free(c);
        return TOOL_EXIT_FAIL;
    }
    amscr_contour_free(c);
    return tool_out_commit(&out) == 0 ? TOOL_EXIT_OK : TOOL_EXIT_FAIL;
}

/* ================================================================ register */
static int prepare(const amscr_params *p, const char *path, const amscr_contour *c, amscr_descriptor **out)
{
    amscr_status st = amscr_descriptor_new(p, c, out);
    if (st != AMSCR_OK) {
        const char *d = lib_detail();
        if (st == AMSCR_E_DEGENERATE)
            tool_error(path, "cannot use this shape: %s", d[0] ? d : "degenerate (too few points, or no area)");
        else
            tool_lib_error(path, st);
        return -1;
    }
    return 0;
}

static int cmd_register(opts *o)
{
    const char *spath = o->pos[0], *tpath = o->pos[1];
    amscr_params *p = NULL;
    amscr_contour *src = NULL, *tgt = NULL;
    amscr_descriptor *ds = NULL, *dt = NULL;
    amscr_result *res = NULL;
    double *scales = NULL, *resid = NULL, *sse = NULL, *after = NULL;
    int *kept = NULL;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);

    int r = make_params(o, 1, &p);
    if (r != 0)
        return r;
    if (shape_load(spath, o->threshold, &src) != 0 || shape_load(tpath, o->threshold, &tgt) != 0)
        goto done;
    if (prepare(p, spath, src, &ds) != 0 || prepare(p, tpath, tgt, &dt) != 0)
        goto done;
    amscr_status st = amscr_register(p, ds, dt, NULL, &res);
    if (st != AMSCR_OK) {
        char what[512];
        snprintf(what, sizeof what, "%s -> %s", spath, tpath);
        tool_lib_error(what, st);
        goto done;
    }
    double m[6];
    st = amscr_result_affine(res, m);
    size_t np = amscr_result_num_scales(res), nsc = 0, nr = np, nk = np, nsse = 0;
    scales = params_scales(p, &nsc);
    resid = xmalloc_array(np ? np : 1, sizeof(double));
    kept = xmalloc_array(np ? np : 1, sizeof(int));
    if (st == AMSCR_OK)
        st = amscr_result_sse(res, NULL, &nsse);
    sse = xcalloc_array(nsse ? nsse : 1, sizeof(double));
    if (st != AMSCR_OK || scales == NULL || resid == NULL || kept == NULL || sse == NULL) {
        if (st != AMSCR_OK)
            tool_lib_error("register", st);
        goto done;
    }
    if (nsc != np) {
        tool_error("register", "the result has %zu scales but the parameters %zu", np, nsc);
        goto done;
    }
    st = amscr_result_residuals(res, resid, &nr);
    if (st == AMSCR_OK)
        st = amscr_result_kept(res, kept, &nk);
    if (st == AMSCR_OK && nsse > 0)
        st = amscr_result_sse(res, sse, &nsse);
    double mw[16], mm[16], mv[16];
    size_t nmix = 16;
    amscr_status stmix = amscr_result_mixture(res, mw, mm, mv, &nmix);
    if (stmix != AMSCR_OK)
        nmix = 0;
    if (st != AMSCR_OK) {
        tool_lib_error("register", st);
        goto done;
    }
    double dist = amscr_result_distance(res), thr = amscr_result_threshold(res);
    size_t shift = amscr_result_shift(res), K = amscr_result_k(res), nkept = amscr_result_num_kept(res);
    int refl = amscr_result_reflected(res);
    const char *mname = method_name(amscr_result_method(res));
    size_t N = amscr_params_get_num_samples(p);

    /* pictures first: a failure there is reported before anything is printed */
    size_t ns = amscr_contour_size(src);
    if (o->overlay) {
        after = xmalloc_array(2 * ns, sizeof(double));
        if (after == NULL)
            goto done;
        st = amscr_affine_apply(m, amscr_contour_xy(src), ns, after);
        if (st != AMSCR_OK) {
            tool_lib_error("register", st);
            goto done;
        }
        char cap[200], d1[32];
        snprintf(cap, sizeof cap, "distance %s, %s, %zu of %zu scales kept%s", fmt_num(d1, dist), mname, nkept, np,
                 refl ? ", reflected" : "");
        overlay_input ov = {amscr_contour_xy(tgt), amscr_contour_size(tgt), amscr_contour_xy(src), ns, after, ns,
                            !o->open, tpath, spath, cap};
        if (draw_overlay(o->overlay, &ov) != 0)
            goto done;
    }
    if (o->plot) {
        char title[600], d1[32];
        snprintf(title, sizeof title, "%s -> %s: %s, distance %s", path_base(spath), path_base(tpath), mname,
                 fmt_num(d1, dist));
        plot_input pi = {scales, resid, kept, np, thr, sse, nsse, K, title};
        if (draw_plot_svg(o->plot, &pi) != 0)
            goto done;
    }

    if (o->json) {
        sb_puts(&b, "{\"source\": ");
        sb_json_str(&b, spath);
        sb_puts(&b, ", \"target\": ");
        sb_json_str(&b, tpath);
        sb_puts(&b, ", \"A\": [[");
        sb_json_num(&b, m[0]);
        sb_puts(&b, ", ");
        sb_json_num(&b, m[1]);
        sb_puts(&b, "], [");
        sb_json_num(&b, m[3]);
        sb_puts(&b, ", ");
        sb_json_num(&b, m[4]);
        sb_puts(&b, "]], \"B\": [");
        sb_json_num(&b, m[2]);
        sb_puts(&b, ", ");
        sb_json_num(&b, m[5]);
        sb_puts(&b, "], \"distance\": ");
        sb_json_num(&b, dist);
        sb_puts(&b, ", \"method\": ");
        sb_json_str(&b, mname);
        sb_puts(&b, ", \"scales\": [");
        for (size_t k = 0; k < np; k++) {
            sb_puts(&b, k ? ", " : "");
            sb_json_num(&b, scales[k]);
        }
        sb_puts(&b, "], \"residuals\": [");
        for (size_t k = 0; k < np; k++) {
            sb_puts(&b, k ? ", " : "");
            sb_json_num(&b, resid[k]);
        }
        sb_puts(&b, "], \"kept\": [");
        for (size_t k = 0, first = 1; k < np; k++)
            if (kept[k]) {
                sb_puts(&b, first ? "" : ", ");
                sb_json_num(&b, scales[k]);
                first = 0;
            }
        sb_printf(&b, "], \"shift\": %zu, \"reflected\": %s, \"k\": %zu, \"threshold\": ", shift,
                  refl ? "true" : "false", K);
        sb_json_num(&b, thr);
        sb_puts(&b, ", \"sse\": [");
        for (size_t k = 0; k < nsse; k++) {
            sb_puts(&b, k ? ", " : "");
            sb_json_num(&b, sse[k]);
        }
        sb_puts(&b, "], \"mixture\": {\"weights\": [");
        for (size_t k = 0; k < nmix; k++) {
            sb_puts(&b, k ? ", " : "");
            sb_json_num(&b, mw[k]);
        }
        sb_puts(&b, "], \"means\": [");
        for (size_t k = 0; k < nmix; k++) {
            sb_puts(&b, k ? ", " : "");
            sb_json_num(&b, mm[k]);
        }
        sb_puts(&b, "], \"variances\": [");
        for (size_t k = 0; k < nmix; k++) {
            sb_puts(&b, k ? ", " : "");
            sb_json_num(&b, mv[k]);
        }
        sb_printf(&b, "]}, \"samples\": %zu, \"closed\": %s, \"source_points\": %zu, \"target_points\": %zu}\n", N,
                  o->open ? "false" : "true", ns, amscr_contour_size(tgt));
    } else {
        char n1[32], n2[32];
        sb_printf(&b, "source      %s (%zu points)\n", spath, ns);
        sb_printf(&b, "target      %s (%zu points)\n", tpath, amscr_contour_size(tgt));
        sb_printf(&b, "method      %s (N = %zu samples, %s curves)\n", mname, N, o->open ? "open" : "closed");
        sb_printf(&b, "distance    %s\n", fmt_num(n1, dist));
        sb_printf(&b, "A           [ %12.6g %12.6g ]\n", m[0], m[1]);
        sb_printf(&b, "            [ %12.6g %12.6g ]\n", m[3], m[4]);
        sb_printf(&b, "B           [ %12.6g %12.6g ]   (target = A * source + B)\n", m[2], m[5]);
        if (K > 0)
            sb_printf(&b, "K           %zu (elbow over K = 1..%zu)\n", K, nsse);
        if (isfinite(thr))
            sb_printf(&b, "threshold   %s (Bayes)\n", fmt_num(n1, thr));
        else
            sb_printf(&b, "threshold   none (every scale kept)\n");
        sb_printf(&b, "kept        %zu of %zu scales:", nkept, np);
        for (size_t k = 0; k < np; k++)
            if (kept[k])
                sb_printf(&b, " %s", fmt_num(n1, scales[k]));
        sb_puts(&b, "\n");
        sb_puts(&b, "residuals  ");
        for (size_t k = 0; k < np; k++)
            sb_printf(&b, " %s:%s%s", fmt_num(n1, scales[k]), fmt_num(n2, resid[k]), kept[k] ? "*" : "");
        sb_puts(&b, "   (scale:residual, * = kept)\n");
        sb_printf(&b, "shift       %zu (of %zu samples)\n", shift, N);
        sb_printf(&b, "reflected   %s\n", refl ? "yes" : "no");
        if (o->overlay)
            sb_printf(&b, "overlay     %s\n", o->overlay);
        if (o->plot)
            sb_printf(&b, "plot        %s\n", o->plot);
    }
    if (b.oom) {
        tool_error(NULL, "out of memory");
        goto done;
    }
    fputs(b.s, stdout);
    if (fflush(stdout) != 0) {
        tool_error("<stdout>", "write error: %s", strerror(errno));
        goto done;
    }
    ret = TOOL_EXIT_OK;
done:
    sb_free(&b);
    free(scales);
    free(resid);
    free(kept);
    free(sse);
    free(after);
    amscr_result_free(res);
    amscr_descriptor_free(ds);
    amscr_descriptor_free(dt);
    amscr_contour_free(src);
    amscr_contour_free(tgt);
    amscr_params_free(p);
    return ret;
}

/* ================================================================ collections */
/* Loads every shape of a collection into a new db (params p). */
static int load_db(const amscr_params *p, const collection *c, int threshold, amscr_db **out)
{
    amscr_db *db = NULL;
    amscr_status st = amscr_db_new(p, &db);
    if (st != AMSCR_OK) {
        tool_lib_error(NULL, st);
        return -1;
    }
    tool_progress pr;
    progress_init(&pr, "preparing shapes");
    for (size_t i = 0; i < c->n; i++) {
        amscr_contour *ct = NULL;
        if (shape_load(c->items[i].path, threshold, &ct) != 0) {
            progress_end(&pr);
            amscr_db_free(db);
            return -1;
        }
        st = amscr_db_add_contour(db, ct, c->items[i].label, NULL);
        amscr_contour_free(ct);
        if (st != AMSCR_OK) {
            progress_end(&pr);
            const char *d = lib_detail();
            if (st == AMSCR_E_DEGENERATE)
                tool_error(c->items[i].path, "cannot use this shape: %s", d[0] ? d : "degenerate");
            else
                tool_lib_error(c->items[i].path, st);
            amscr_db_free(db);
            return -1;
        }
        progress_update(&pr, i + 1, c->n);
    }
    progress_end(&pr);
    *out = db;
    return 0;
}

static int compute_matrix(const amscr_db *db, const char *what, const opts *o, double **out)
{
    size_t n = amscr_db_size(db);
    if (n != 0 && n > SIZE_MAX / n / sizeof(double)) {
        tool_error(what, "too many shapes for a matrix (%zu)", n);
        return -1;
    }
    double *d = xmalloc_array(n * n, sizeof(double));
    if (d == NULL)
        return -1;
    tool_progress pr;
    progress_init(&pr, "matching");
    amscr_status st = amscr_db_distance_matrix(db, progress_cb, &pr, d);
    progress_end(&pr);
    if (st == AMSCR_OK && o->rerank_k > 0 && n > 0)
        st = amscr_rerank_diffusion(d, n, o->rerank_k < n ? o->rerank_k : n, o->rerank_iters, d);
    if (st != AMSCR_OK) {
        tool_lib_error(what, st);
        free(d);
        return -1;
    }
    *out = d;
    return 0;
}

static int cmd_search(opts *o)
{
    const char *qpath = o->pos[0], *cpath = o->pos[1];
    amscr_params *p = NULL;
    collection c;
    amscr_db *db = NULL;
    amscr_contour *q = NULL;
    amscr_descriptor *dq = NULL;
    double *dist = NULL;
    size_t *idx = NULL;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);
    memset(&c, 0, sizeof c);
    double t0 = now_seconds();

    int r = make_params(o, 0, &p);
    if (r != 0)
        return r;
    if (shape_load(qpath, o->threshold, &q) != 0)
        goto done;
    if (collection_open(cpath, &c) != 0)
        goto done;
    if (load_db(p, &c, o->threshold, &db) != 0)
        goto done;
    if (prepare(amscr_db_params(db), qpath, q, &dq) != 0)
        goto done;
    size_t n = amscr_db_size(db);
    dist = xmalloc_array(n, sizeof(double));
    size_t k = o->top < n ? o->top : n;
    idx = xmalloc_array(k ? k : 1, sizeof(size_t));
    if (dist == NULL || idx == NULL)
        goto done;
    amscr_status st = AMSCR_OK;
    if (o->rerank_k > 0) {
        /* contextual re-ranking needs the whole matrix of the collection and the query */
        double *full = NULL;
        if (amscr_db_add_descriptor(db, dq, -1, NULL) != AMSCR_OK) {
            tool_lib_error(qpath, AMSCR_E_NOMEM);
            goto done;
        }
        if (compute_matrix(db, cpath, o, &full) != 0)
            goto done;
        for (size_t j = 0; j < n; j++)
            dist[j] = full[n * (n + 1) + j]; /* the query's row (last), collection columns */
        free(full);
    } else {
        tool_progress pr;
        progress_init(&pr, "matching");
        st = amscr_db_query(db, dq, progress_cb, &pr, dist);
        progress_end(&pr);
    }
    if (st == AMSCR_OK)
        st = amscr_topk(dist, n, k, SIZE_MAX, idx);
    if (st != AMSCR_OK) {
        tool_lib_error(qpath, st);
        goto done;
    }
    double secs = now_seconds() - t0;
    if (o->json) {
        sb_puts(&b, "{\"query\": ");
        sb_json_str(&b, qpath);
        sb_puts(&b, ", \"collection\": ");
        sb_json_str(&b, cpath);
        sb_printf(&b, ", \"n\": %zu, \"results\": [", n);
        for (size_t i = 0; i < k; i++) {
            const coll_item *it = &c.items[idx[i]];
            sb_printf(&b, "%s{\"rank\": %zu, \"index\": %zu, \"file\": ", i ? ", " : "", i + 1, idx[i]);
            sb_json_str(&b, it->name);
            sb_puts(&b, ", \"class\": ");
            sb_json_str(&b, c.classes[it->label]);
            sb_puts(&b, ", \"distance\": ");
            sb_json_num(&b, dist[idx[i]]);
            sb_puts(&b, "}");
        }
        sb_puts(&b, "], \"seconds\": ");
        sb_json_num(&b, secs);
        sb_puts(&b, "}\n");
    } else {
        sb_printf(&b, "query %s against %s (%zu shapes, %.2f s)\n", qpath, cpath, n, secs);
        sb_printf(&b, "%4s  %-12s  %-16s  %s\n", "rank", "distance", "class", "file");
        char d1[32];
        for (size_t i = 0; i < k; i++) {
            const coll_item *it = &c.items[idx[i]];
            sb_printf(&b, "%4zu  %-12s  %-16s  %s\n", i + 1, fmt_num(d1, dist[idx[i]]), c.classes[it->label],
                      it->name);
        }
    }
    if (b.oom) {
        tool_error(NULL, "out of memory");
        goto done;
    }
    fputs(b.s, stdout);
    ret = fflush(stdout) == 0 ? TOOL_EXIT_OK : TOOL_EXIT_FAIL;
done:
    sb_free(&b);
    free(dist);
    free(idx);
    amscr_descriptor_free(dq);
    amscr_contour_free(q);
    amscr_db_free(db);
    collection_free(&c);
    amscr_params_free(p);
    return ret;
}

/* .npy v1.0: magic, version, little-endian u16 header length, a Python dict literal
 * padded with spaces and '\n' so the data starts at a multiple of 64 bytes. */
static int write_npy(FILE *fp, const double *d, size_t n)
{
    char dict[128];
    snprintf(dict, sizeof dict, "{'descr': '<f8', 'fortran_order': False, 'shape': (%zu, %zu), }", n, n);
    size_t dl = strlen(dict);
    size_t total = 10 + dl + 1;
    size_t pad = (64 - total % 64) % 64;
    size_t hlen = dl + pad + 1;
    if (hlen > 65535)
        return -1;
    unsigned char pre[10] = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, (unsigned char)(hlen & 0xff),
                             (unsigned char)(hlen >> 8)};
    if (fwrite(pre, 1, 10, fp) != 10 || fwrite(dict, 1, dl, fp) != dl)
        return -1;
    for (size_t i = 0; i < pad; i++)
        if (fputc(' ', fp) == EOF)
            return -1;
    if (fputc('\n', fp) == EOF)
        return -1;
    const uint16_t one = 1;
    int little = *(const unsigned char *)&one == 1;
    for (size_t i = 0; i < n * n; i++) {
        unsigned char bytes[8];
        memcpy(bytes, &d[i], 8);
        if (!little)
            for (int k = 0; k < 4; k++) {
                unsigned char t = bytes[k];
                bytes[k] = bytes[7 - k];
                bytes[7 - k] = t;
            }
        if (fwrite(bytes, 1, 8, fp) != 8)
            return -1;
    }
    return 0;
}

static int write_tsv(FILE *fp, const double *d, size_t n, const collection *c)
{
    if (fputs("#", fp) == EOF)
        return -1;
    for (size_t j = 0; j < n; j++) {
        /* names with tabs or newlines would break the comment line */
        fputc(j ? '\t' : ' ', fp);
        for (const char *s = c->items[j].name; *s; s++)
            fputc(*s == '\t' || *s == '\n' || *s == '\r' ? ' ' : *s, fp);
    }
    fputc('\n', fp);
    for (size_t i = 0; i < n; i++) {
        for (size_t j = 0; j < n; j++)
            if (fprintf(fp, "%s%.17g", j ? "\t" : "", d[i * n + j]) < 0)
                return -1;
        if (fputc('\n', fp) == EOF)
            return -1;
    }
    return ferror(fp) ? -1 : 0;
}

static int cmd_matrix(opts *o)
{
    const char *cpath = o->pos[0];
    if (o->out == NULL)
        return usage_error("matrix", "missing -o FILE (.tsv, .npy, or - for stdout)");
    char ext[16];
    path_ext(o->out, ext);
    int npy = strcmp(ext, ".npy") == 0;
    if (!npy && strcmp(ext, ".tsv") != 0 && strcmp(ext, ".txt") != 0 && strcmp(o->out, "-") != 0)
        return usage_error("-o", "'%s': the matrix file must end in .tsv or .npy (or be - for stdout)", o->out);
    amscr_params *p = NULL;
    collection c;
    amscr_db *db = NULL;
    double *d = NULL;
    int ret = TOOL_EXIT_FAIL;
    memset(&c, 0, sizeof c);
    int r = make_params(o, 0, &p);
    if (r != 0)
        return r;
    if (collection_open(cpath, &c) != 0 || load_db(p, &c, o->threshold, &db) != 0 ||
        compute_matrix(db, cpath, o, &d) != 0)
        goto done;
    size_t n = c.n;
    tool_out out;
    if (tool_out_open(&out, o->out) != 0)
        goto done;
    if ((npy ? write_npy(out.fp, d, n) : write_tsv(out.fp, d, n, &c)) != 0) {
        tool_error(o->out, "write error: %s", strerror(errno));
        tool_out_abort(&out);
        goto done;
    }
    if (o->names) {
        tool_out nf;
        if (tool_out_open(&nf, o->names) != 0) {
            tool_out_abort(&out);
            goto done;
        }
        fputs("file\tclass\n", nf.fp);
        for (size_t i = 0; i < n; i++)
            fprintf(nf.fp, "%s\t%s\n", c.items[i].name, c.classes[c.items[i].label]);
        if (tool_out_commit(&nf) != 0) {
            tool_out_abort(&out);
            goto done;
        }
    }
    if (tool_out_commit(&out) != 0)
        goto done;
    if (isatty(2) && strcmp(o->out, "-") != 0)
        fprintf(stderr, "amscr: wrote %s (%zu x %zu)\n", o->out, n, n);
    ret = TOOL_EXIT_OK;
done:
    free(d);
    amscr_db_free(db);
    collection_free(&c);
    amscr_params_free(p);
    return ret;
}

static int cmd_eval(opts *o)
{
    const char *cpath = o->pos[0];
    const char *proto = o->protocol ? o->protocol : "all";
    int want_be = name_is(proto, "all") || name_is(proto, "bullseye");
    int want_tk = name_is(proto, "all") || name_is(proto, "topk");
    int want_nn = name_is(proto, "all") || name_is(proto, "nn");
    amscr_params *p = NULL;
    collection c;
    amscr_db *db = NULL;
    double *d = NULL;
    int32_t *labels = NULL;
    size_t *counts = NULL;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);
    memset(&c, 0, sizeof c);
    double t0 = now_seconds();
    int r = make_params(o, 0, &p);
    if (r != 0)
        return r;
    if (collection_open(cpath, &c) != 0)
        goto done;
    if (c.n < 2) {
        tool_error(cpath, "eval needs at least 2 shapes, found %zu", c.n);
        goto done;
    }
    if (load_db(p, &c, o->threshold, &db) != 0)
        goto done;
    double t1 = now_seconds();
    if (compute_matrix(db, cpath, o, &d) != 0)
        goto done;
    double t2 = now_seconds();
    size_t n = c.n;
    labels = xmalloc_array(n, sizeof(int32_t));
    size_t ranks = o->ranks ? o->ranks : 10;
    if (ranks > n - 1)
        ranks = n - 1;
    counts = xcalloc_array(ranks, sizeof(size_t));
    if (labels == NULL || counts == NULL)
        goto done;
    for (size_t i = 0; i < n; i++)
        labels[i] = c.items[i].label;
    double be = NAN, nn = NAN;
    amscr_status st = AMSCR_OK;
    if (want_be)
        st = amscr_score_bullseye(d, n, labels, 0, &be);
    if (st == AMSCR_OK && want_tk)
        st = amscr_score_topk_table(d, n, labels, ranks, counts);
    if (st == AMSCR_OK && want_nn)
        st = amscr_score_nn_accuracy(d, n, labels, &nn);
    if (st != AMSCR_OK) {
        tool_lib_error(cpath, st);
        goto done;
    }
    double secs = now_seconds() - t0;
    const char *mname = method_name(amscr_params_get_method(p));
    int refl = amscr_params_get_reflections(p);
    if (o->json) {
        sb_puts(&b, "{\"collection\": ");
        sb_json_str(&b, cpath);
        sb_printf(&b, ", \"n\": %zu, \"classes\": %zu, \"protocol\": ", n, c.nclasses);
        sb_json_str(&b, proto);
        if (want_be) {
            sb_puts(&b, ", \"bullseye\": ");
            sb_json_num(&b, be);
        }
        if (want_tk) {
            sb_puts(&b, ", \"topk\": [");
            for (size_t k = 0; k < ranks; k++)
                sb_printf(&b, "%s%zu", k ? ", " : "", counts[k]);
            sb_puts(&b, "]");
        }
        if (want_nn) {
            sb_puts(&b, ", \"nn_accuracy\": ");
            sb_json_num(&b, nn);
        }
        sb_puts(&b, ", \"method\": ");
        sb_json_str(&b, mname);
        sb_printf(&b, ", \"reflections\": %s, \"seconds\": ", refl ? "true" : "false");
        sb_json_num(&b, secs);
        sb_puts(&b, ", \"seconds_prepare\": ");
        sb_json_num(&b, t1 - t0);
        sb_puts(&b, ", \"seconds_matrix\": ");
        sb_json_num(&b, t2 - t1);
        sb_puts(&b, "}\n");
    } else {
        sb_printf(&b, "collection  %s (%zu shapes, %zu classes)\n", cpath, n, c.nclasses);
        sb_printf(&b, "method      %s, N = %zu, reflections %s\n", mname, amscr_params_get_num_samples(p),
                  refl ? "on" : "off");
        if (want_be)
            sb_printf(&b, "bull's eye  %.2f %%  (same class among the 2*Nc nearest)\n", 100.0 * be);
        if (want_tk) {
            sb_printf(&b, "top-k       ");
            for (size_t k = 0; k < ranks; k++)
                sb_printf(&b, "%s%zu", k ? " " : "", counts[k]);
            sb_printf(&b, "  (ranks 1..%zu, of %zu queries)\n", ranks, n);
        }
        if (want_nn)
            sb_printf(&b, "1-NN        %.2f %%  (leave-one-out)\n", 100.0 * nn);
        sb_printf(&b, "seconds     %.2f  (prepare %.2f, matrix %.2f: %.0f pairs/s)\n", secs, t1 - t0, t2 - t1,
                  t2 > t1 ? (double)n * (double)(n - 1) / (t2 - t1) : 0.0);
    }
    if (b.oom) {
        tool_error(NULL, "out of memory");
        goto done;
    }
    fputs(b.s, stdout);
    ret = fflush(stdout) == 0 ? TOOL_EXIT_OK : TOOL_EXIT_FAIL;
done:
    sb_free(&b);
    free(d);
    free(labels);
    free(counts);
    amscr_db_free(db);
    collection_free(&c);
    amscr_params_free(p);
    return ret;
}

/* ================================================================ main */
int main(int argc, char **argv)
{
    if (argc < 2)
        return usage_error(NULL, "missing command: contour, register, search, matrix or eval (see 'amscr --help')");
    const char *cmd = argv[1];
    if (strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0 || strcmp(cmd, "help") == 0) {
        if (strcmp(cmd, "help") == 0 && argc > 2) {
            const char *c2 = argv[2];
            if (strcmp(c2, "contour") == 0 || strcmp(c2, "register") == 0 || strcmp(c2, "search") == 0 ||
                strcmp(c2, "matrix") == 0 || strcmp(c2, "eval") == 0) {
                print_cmd_help(c2);
                return TOOL_EXIT_OK;
            }
        }
        fputs(HELP_MAIN, stdout);
        return TOOL_EXIT_OK;
    }
    if (strcmp(cmd, "--version") == 0 || strcmp(cmd, "-V") == 0 || strcmp(cmd, "version") == 0) {
        printf("%s\n", amscr_version_string());
        return TOOL_EXIT_OK;
    }
    opts o;
    memset(&o, 0, sizeof o);
    o.cmd = cmd;
    o.threshold = 127;
    o.reflections = -1;
    o.top = 10;
    /* retrieval defaults, chosen by the Kimia measurements in the README: contextual
     * re-ranking with K = 5 (20 iterations); --no-rerank for the plain pairwise distance */
    o.rerank_k = 5;
    o.rerank_iters = 20;
    int minpos, maxpos;
    const char *posnames;
    if (strcmp(cmd, "contour") == 0) {
        o.cmd_bit = C_CONTOUR;
        minpos = maxpos = 1;
        posnames = "IMG [-o FILE]";
    } else if (strcmp(cmd, "register") == 0) {
        o.cmd_bit = C_REGISTER;
        minpos = maxpos = 2;
        posnames = "SRC TGT";
    } else if (strcmp(cmd, "search") == 0) {
        o.cmd_bit = C_SEARCH;
        minpos = maxpos = 2;
        posnames = "QUERY COLLECTION";
    } else if (strcmp(cmd, "matrix") == 0) {
        o.cmd_bit = C_MATRIX;
        minpos = maxpos = 1;
        posnames = "COLLECTION -o FILE";
    } else if (strcmp(cmd, "eval") == 0) {
        o.cmd_bit = C_EVAL;
        minpos = maxpos = 1;
        posnames = "COLLECTION";
    } else {
        return usage_error(NULL, "unknown command '%s' (see 'amscr --help')", cmd);
    }
    int r = parse_args(&o, argc, argv, minpos, maxpos, posnames);
    if (r < 0)
        return TOOL_EXIT_OK; /* help */
    if (r != 0)
        return r;
    switch (o.cmd_bit) {
    case C_CONTOUR: return cmd_contour(&o);
    case C_REGISTER: return cmd_register(&o);
    case C_SEARCH: return cmd_search(&o);
    case C_MATRIX: return cmd_matrix(&o);
    default: return cmd_eval(&o);
    }
}
