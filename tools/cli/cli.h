/* cli.h — the command line of the amscr tool: the parsed options, the command table and the
 * command handlers. Tool-internal.
 *
 *   options.c   the option table (name -> option id) and the parser
 *   commands.c  the command table (name, usage, help, handler) and the help texts
 *   cmd_*.c     one handler per command */
#ifndef AMSCR_TOOL_CLI_H
#define AMSCR_TOOL_CLI_H

#include <stddef.h>

#include "amscr.h"
#include "util.h"

/* Command bits: an option lists the commands that accept it. */
enum {
    C_CONTOUR = 1,
    C_REGISTER = 2,
    C_SEARCH = 4,
    C_MATRIX = 8,
    C_EVAL = 16,
    C_INDEX = 32,
    C_SHAPES = C_REGISTER | C_SEARCH | C_MATRIX | C_EVAL | C_INDEX,
    C_RETRIEVAL = C_SEARCH | C_MATRIX | C_EVAL | C_INDEX,
    C_ALL = 63
};

/* Defaults and limits of the tool's own options (the shape parameters' defaults are the
 * library's, see cmd_params.c). */
enum {
    TOOL_THRESHOLD_DEFAULT = 127, /* pixels > 127 are 'on': mid-grey of 8 bits */
    TOOL_THRESHOLD_UNSET = -2,    /* no --threshold: 127, or 0 on an image of only 0s and 1s */
    TOOL_THRESHOLD_MAX = 254,     /* > 254 leaves no pixel on */
    TOOL_TOP_DEFAULT = 10,        /* search results */
    TOOL_RANKS_DEFAULT = 10,      /* ranks of the top-k table (Kimia-99's table has 10) */
    /* --rerank K without ITER: the iterations of the library's retrieval preset (10) */
    TOOL_RERANK_ITERS = 10,
    TOOL_TOP_MAX = 1000000000,    /* --top: a bound that keeps k * sizeof(size_t) small */
    TOOL_RANKS_MAX = 1000000,     /* --ranks: likewise for the top-k table */
    TOOL_RERANK_K_MAX = 1000,     /* --rerank K: the library's range; clamped to the collection at use */
    TOOL_RERANK_ITERS_MAX = 1000, /* --rerank ITER: diffusion converges long before */
    TOOL_POINTS_MIN = 16,         /* the library's range of samples: 16..AMSCR_MAX_SAMPLES */
    TOOL_REFINE_MAX = 50,         /* the library's range of refinement iterations */
    TOOL_STAGES_MAX = 8,          /* register --stage: more than the switchable stages */
    TOOL_KMAX_MAX = 16,           /* the library's range of the elbow's Kmax */
    TOOL_THREADS_MAX = 1024,      /* the library's range of threads */
    TOOL_SPLITS_DEFAULT = 10,     /* eval --protocol split: random splits averaged */
    TOOL_SPLITS_MAX = 100000,     /* a bound on the work, far above any useful spread estimate */
    TOOL_SEED_DEFAULT = 1,        /* eval --protocol split: the splits are reproducible */
    /* contour --all: contours enclosing fewer pixels^2 are specks of noise (a 4 x 4 square
     * through pixel centres has area 9) */
    TOOL_MIN_AREA_DEFAULT = 10,
    /* search against an index: the library's default shortlist (AMSCR_INDEX_CANDIDATES shapes
     * whose signatures are nearest the query's; docs/measurements.md, "The index"); every
     * shape when the index is no larger. An index is built from every pair unless told
     * --candidates M. */
    TOOL_CANDIDATES_DEFAULT = AMSCR_INDEX_CANDIDATES
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
    const char *sheet; /* search --sheet FILE */
    int all;           /* contour --all */
    int join;          /* contour --join */
    double min_area;   /* --min-area A (pixels^2) */
    int min_area_set;
    long component;    /* --component N; -1: the largest outer contour */
    int add;           /* index --add */
    size_t candidates; /* search against an index: shapes matched (0: all) */
    int candidates_set;
    const char *names;
    size_t top;
    const char *protocol; /* as given (printed back by eval --json); NULL: all */
    int protocol_id;      /* PROTO_* (names.h) */
    size_t ranks;
    size_t train;       /* --train K: training shapes per class (protocol split); 0: not given */
    size_t splits;      /* --splits R (default TOOL_SPLITS_DEFAULT) */
    unsigned long long seed; /* --seed S (default TOOL_SEED_DEFAULT) */
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
    int partial; /* register --partial */
    int no_polish; /* register --no-polish (0.3) */
    char stage_name[TOOL_STAGES_MAX][32]; /* register --stage NAME=on|off (0.5), in order given */
    int stage_on[TOOL_STAGES_MAX];
    size_t nstages;
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
    /* retrieval (search/matrix/eval; set only when given, else the library's retrieval preset) */
    int rerank_set;
    size_t rerank_k; /* 0: no contextual re-ranking */
    unsigned rerank_iters;
    int channel_weight_set;
    double channel_weight;
    int affine_share_set;
    double affine_share;
    int inner_share_set;
    double inner_share;
    int inner_closing_set;
    double inner_closing;
    int affine_view_set;
    double affine_view; /* 0: the frames mixed by the share for every pair */
} opts;

typedef struct tool_command {
    const char *name;
    int bit;              /* C_* */
    int npos;             /* positional arguments */
    const char *args;     /* "SRC TGT": usage errors and the main help */
    const char *summary;  /* one line of the main help */
    const char *help;     /* `amscr NAME --help` */
    int shape_options;    /* the help goes on with the image and shape options */
    int (*run)(opts *o);
} tool_command;

/* commands.c */
const tool_command *command_find(const char *name);
/* "contour, register, search, matrix or eval" */
const char *command_list(char *buf, size_t cap);
void print_main_help(void);
/* Prints `amscr NAME --help`; returns the exit code. */
int print_command_help(const tool_command *c);

/* options.c */
/* The options before parsing: the command's defaults. */
void opts_init(opts *o, const tool_command *c);
/* Parses argv[2..]. Returns 0, TOOL_EXIT_USAGE, or -1 when --help (-h) was asked. */
int parse_args(opts *o, const tool_command *c, int argc, char **argv);

/* The handlers (cmd_*.c): each returns the exit code. */
int cmd_contour(opts *o);
int cmd_register(opts *o);
int cmd_search(opts *o);
int cmd_matrix(opts *o);
int cmd_eval(opts *o);
int cmd_index(opts *o);

#endif
