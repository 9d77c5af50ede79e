/* cmd_eval.c — `amscr eval COLLECTION`: retrieval scores of a labelled collection. */
#include <math.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "collection.h"
#include "eval_plot.h"
#include "index_tool.h"
#include "json.h"
#include "names.h"
#include "cmd_params.h"
#include "shape_db.h"

/* The scores the protocol asks for, and the times of the steps. */
typedef struct eval_scores {
    int want_be, want_tk, want_nn;
    double be, nn;
    size_t *counts; /* top-k table, ranks entries */
    size_t ranks;
    double t0, t1, t2, secs; /* start, db prepared, matrix done; total seconds */
    double *cls_nn, *cls_be; /* per class (leave-one-out), when nn / bull's eye are computed */
    size_t *sizes;           /* class sizes */
    int32_t *labels;         /* n class indices (the collection's labels) */
    int want_split, want_groups, want_nn_classes;
    double split_mean, split_std, *split_acc, *split_cls; /* split: splits and nclasses entries */
    double groups_acc, *groups_grp, *groups_cls;         /* groups: ngroups and nclasses entries */
} eval_scores;

/* The collection's class labels (malloc'ed, n entries), and with sizes non-NULL the class sizes
 * (malloc'ed, nclasses entries, amscr_score_classes: the classes are the labels 0..nclasses-1). */
static int32_t *collection_labels(const collection *c, size_t **sizes)
{
    int32_t *l = xmalloc_array(c->n ? c->n : 1, sizeof(int32_t));
    if (l == NULL)
        return NULL;
    for (size_t i = 0; i < c->n; i++)
        l[i] = c->items[i].label;
    size_t nc = c->nclasses;
    if (sizes && ((*sizes = xmalloc_array(nc ? nc : 1, sizeof(size_t))) == NULL ||
                  amscr_score_classes(l, c->n, NULL, *sizes, &nc) != AMSCR_OK)) {
        free(*sizes);
        *sizes = NULL;
        free(l);
        return NULL;
    }
    return l;
}

/* The matrix of the groups protocol: each group's shapes as new queries against the collection
 * without the group (amscr_db_retrieval_matrix_heldout: its fusion and re-ranking graph held
 * out too); the distance matrix as is when nothing of the collection's enters the ranking. */
static int heldout_matrix(const amscr_db *db, const collection *c, const char *what, double **out)
{
    size_t n = c->n;
    if (retrieval_is_plain(amscr_db_params(db)))
        return compute_matrix(db, what, out);
    if (n > SIZE_MAX / n / sizeof(double)) {
        tool_error(what, "too many shapes for a matrix (%zu)", n);
        return -1;
    }
    double *d = xmalloc_array(n * n, sizeof(double));
    int32_t *g = xmalloc_array(n, sizeof(int32_t));
    if (d == NULL || g == NULL) {
        free(d);
        free(g);
        return -1;
    }
    for (size_t i = 0; i < n; i++)
        g[i] = c->items[i].group;
    tool_progress pr;
    progress_init(&pr, "matching");
    amscr_status st = amscr_db_retrieval_matrix_heldout(db, g, n, progress_cb, &pr, d);
    progress_end(&pr);
    free(g);
    if (st != AMSCR_OK) {
        tool_lib_error(what, st);
        free(d);
        return -1;
    }
    *out = d;
    return 0;
}

/* Leave one group out (amscr_score_nn_groups). */
static amscr_status compute_groups(const double *d, const collection *c, eval_scores *s)
{
    size_t nc = c->nclasses, n = c->n;
    int32_t *g = xmalloc_array(n, sizeof(int32_t));
    s->groups_grp = xmalloc_array(c->ngroups, sizeof(double));
    s->groups_cls = xmalloc_array(nc, sizeof(double));
    if (!g || !s->groups_grp || !s->groups_cls) {
        free(g);
        return AMSCR_E_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        g[i] = c->items[i].group;
    amscr_status st = amscr_score_nn_groups(d, n, s->labels, g, c->ngroups, nc, &s->groups_acc, s->groups_grp,
                                            s->groups_cls);
    free(g);
    return st;
}

/* The per-class scores and the split / groups protocols (the library's amscr_score_per_class,
 * amscr_score_nn_random_split, amscr_score_nn_groups). */
static int compute_protocols(const double *d, const collection *c, const opts *o, const char *cpath, eval_scores *s)
{
    size_t nc = c->nclasses, n = c->n;
    if (o->plot && !s->want_be && !s->want_nn && !s->want_split && !s->want_groups)
        s->want_nn_classes = 1; /* the plot's bars */
    if ((s->want_nn_classes || s->want_nn) && (s->cls_nn = xmalloc_array(nc, sizeof(double))) == NULL)
        return -1;
    if (s->want_be && (s->cls_be = xmalloc_array(nc, sizeof(double))) == NULL)
        return -1;
    amscr_status st = AMSCR_OK;
    if (s->cls_nn || s->cls_be)
        st = amscr_score_per_class(d, n, s->labels, nc, s->cls_be, s->cls_nn);
    if (st == AMSCR_OK && s->want_split) {
        s->split_acc = xmalloc_array(o->splits, sizeof(double));
        s->split_cls = xmalloc_array(nc, sizeof(double));
        if (!s->split_acc || !s->split_cls)
            return -1;
        st = amscr_score_nn_random_split(d, n, s->labels, o->train, o->splits, (uint64_t)o->seed, nc, &s->split_mean,
                                         &s->split_std, s->split_acc, s->split_cls);
    }
    if (st == AMSCR_OK && s->want_groups)
        st = compute_groups(d, c, s);
    if (st != AMSCR_OK) {
        tool_lib_error(cpath, st);
        return -1;
    }
    return 0;
}

static int compute_scores(const double *d, const collection *c, const opts *o, const char *cpath, eval_scores *s)
{
    size_t n = c->n;
    const int32_t *labels = s->labels = collection_labels(c, &s->sizes);
    s->counts = xcalloc_array(s->ranks, sizeof(size_t));
    if (labels == NULL || s->counts == NULL)
        return -1;
    amscr_status st = AMSCR_OK;
    if (s->want_be)
        st = amscr_score_bullseye(d, n, labels, 0, &s->be);
    if (st == AMSCR_OK && s->want_tk)
        st = amscr_score_topk_table(d, n, labels, s->ranks, s->counts);
    if (st == AMSCR_OK && s->want_nn)
        st = amscr_score_nn_accuracy(d, n, labels, &s->nn);
    if (st != AMSCR_OK) {
        tool_lib_error(cpath, st);
        return -1;
    }
    return compute_protocols(d, c, o, cpath, s);
}

/* ", \"split\": {...}, \"groups\": {...}, \"per_class\": [...]" as computed. */
static void json_protocols(sbuf *b, const opts *o, const collection *c, const eval_scores *s)
{
    if (s->want_split) {
        sb_printf(b, ", \"split\": {\"train\": %zu, \"splits\": %zu, \"seed\": %llu, \"accuracy_mean\": ", o->train,
                  o->splits, o->seed);
        sb_json_num(b, s->split_mean);
        sb_puts(b, ", \"accuracy_std\": ");
        sb_json_num(b, s->split_std);
        sb_puts(b, ", \"accuracies\": ");
        sb_json_nums(b, s->split_acc, NULL, o->splits);
        sb_puts(b, "}");
    }
    if (s->want_groups) {
        sb_printf(b, ", \"groups\": {\"n\": %zu, \"accuracy\": ", c->ngroups);
        sb_json_num(b, s->groups_acc);
        sb_puts(b, ", \"per_group\": [");
        for (size_t g = 0; g < c->ngroups; g++) {
            sb_puts(b, g ? ", {\"group\": " : "{\"group\": ");
            sb_json_str(b, c->groups[g]);
            sb_puts(b, ", \"accuracy\": ");
            sb_json_num(b, s->groups_grp[g]);
            sb_puts(b, "}");
        }
        sb_puts(b, "]}");
    }
    sb_puts(b, ", \"per_class\": [");
    for (size_t k = 0; k < c->nclasses; k++) {
        sb_puts(b, k ? ", {\"class\": " : "{\"class\": ");
        sb_json_str(b, c->classes[k]);
        sb_printf(b, ", \"n\": %zu", s->sizes[k]);
        if (s->cls_be) {
            sb_puts(b, ", \"bullseye\": ");
            sb_json_num(b, s->cls_be[k]);
        }
        if (s->cls_nn) {
            sb_puts(b, ", \"nn_accuracy\": ");
            sb_json_num(b, s->cls_nn[k]);
        }
        if (s->want_split) {
            sb_puts(b, ", \"split_accuracy\": ");
            sb_json_num(b, s->split_cls[k]);
        }
        if (s->want_groups) {
            sb_puts(b, ", \"groups_accuracy\": ");
            sb_json_num(b, s->groups_cls[k]);
        }
        sb_puts(b, "}");
    }
    sb_puts(b, "]");
}

static void format_json(sbuf *b, const opts *o, const collection *c, const amscr_params *p, const eval_scores *s)
{
    const char *proto = name_of(&PROTOCOL_NAMES, o->protocol_id); /* the canonical name, as typed or not */
    sb_puts(b, "{\"collection\": ");
    sb_json_str(b, o->pos[0]);
    sb_printf(b, ", \"n\": %zu, \"classes\": %zu, \"protocol\": ", c->n, c->nclasses);
    sb_json_str(b, proto);
    if (s->want_be) {
        sb_puts(b, ", \"bullseye\": ");
        sb_json_num(b, s->be);
    }
    if (s->want_tk) {
        sb_puts(b, ", \"topk\": ");
        sb_json_counts(b, s->counts, s->ranks);
    }
    if (s->want_nn) {
        sb_puts(b, ", \"nn_accuracy\": ");
        sb_json_num(b, s->nn);
    }
    json_protocols(b, o, c, s);
    sb_puts(b, ", \"method\": ");
    sb_json_str(b, name_of(&METHOD_NAMES, (int)amscr_params_get_method(p)));
    sb_printf(b, ", \"reflections\": %s, \"seconds\": ", amscr_params_get_reflections(p) ? "true" : "false");
    sb_json_num(b, s->secs);
    sb_puts(b, ", \"seconds_prepare\": ");
    sb_json_num(b, s->t1 - s->t0);
    sb_puts(b, ", \"seconds_matrix\": ");
    sb_json_num(b, s->t2 - s->t1);
    sb_puts(b, "}\n");
}

static void format_text(sbuf *b, const opts *o, const collection *c, const amscr_params *p, const eval_scores *s)
{
    size_t n = c->n;
    double tm = s->t2 - s->t1;
    sb_printf(b, "collection  %s (%zu shapes, %zu class%s)\n", o->pos[0], n, c->nclasses, c->nclasses == 1 ? "" : "es");
    sb_printf(b, "method      %s, N = %zu, reflections %s\n", name_of(&METHOD_NAMES, (int)amscr_params_get_method(p)),
              amscr_params_get_num_samples(p), amscr_params_get_reflections(p) ? "on" : "off");
    if (s->want_be)
        sb_printf(b, "bull's eye  %.2f %%  (same class among the 2*Nc nearest)\n", 100.0 * s->be);
    if (s->want_tk) {
        sb_printf(b, "top-k       ");
        for (size_t k = 0; k < s->ranks; k++)
            sb_printf(b, "%s%zu", k ? " " : "", s->counts[k]);
        sb_printf(b, "  (ranks 1..%zu, of %zu queries)\n", s->ranks, n);
    }
    if (s->want_nn)
        sb_printf(b, "1-NN        %.2f %%  (leave-one-out)\n", 100.0 * s->nn);
    if (s->want_split)
        sb_printf(b, "split       %.2f %% +- %.2f  (1-NN, %zu per class trained, %zu splits, seed %llu)\n",
                  100.0 * s->split_mean, 100.0 * s->split_std, o->train, o->splits, o->seed);
    if (s->want_groups)
        sb_printf(b, "groups      %.2f %%  (1-NN, leave one of %zu groups out)\n", 100.0 * s->groups_acc, c->ngroups);
    sb_printf(b, "seconds     %.2f  (prepare %.2f, matrix %.2f: %.0f pairs/s)\n", s->secs, s->t1 - s->t0, tm,
              s->t2 > s->t1 ? (double)n * (double)(n - 1) / tm : 0.0);
}

enum { PR_LEVELS = 21 }; /* recall 0, 0.05, ..., 1 */

/* --plot: the per-class scores the protocol computed and the precision-recall curve
 * (amscr_score_precision_recall). */
static int draw_plot(const opts *o, const double *d, const collection *c, const eval_scores *s)
{
    double rec[PR_LEVELS], prec[PR_LEVELS];
    score_series ser[4];
    size_t ns = 0;
    amscr_status st = amscr_score_precision_recall(d, c->n, s->labels, PR_LEVELS, prec);
    if (st != AMSCR_OK) {
        tool_lib_error(o->pos[0], st);
        return -1;
    }
    for (size_t l = 0; l < PR_LEVELS; l++)
        rec[l] = (double)l / (PR_LEVELS - 1);
    if (s->cls_nn)
        ser[ns++] = (score_series){"1-NN (leave one out)", s->cls_nn};
    if (s->cls_be)
        ser[ns++] = (score_series){"bull's eye", s->cls_be};
    if (s->want_split)
        ser[ns++] = (score_series){"1-NN (random split, mean)", s->split_cls};
    if (s->want_groups)
        ser[ns++] = (score_series){"1-NN (leave one group out)", s->groups_cls};
    char title[600];
    snprintf(title, sizeof title, "%s: %zu shapes, %zu class%s", path_base(o->pos[0]), c->n, c->nclasses,
             c->nclasses == 1 ? "" : "es");
    eval_plot_input in = {title, c->classes, c->nclasses, ser, ns, rec, prec, PR_LEVELS};
    return draw_eval_plot(o->plot, &in);
}

/* 0 when every class has more than `train` shapes; otherwise prints the error naming the
 * smallest such class and returns TOOL_EXIT_USAGE. */
static int split_check(const collection *c, size_t train)
{
    size_t *sz = NULL, worst = 0;
    int32_t *l = collection_labels(c, &sz);
    free(l);
    if (l == NULL)
        return TOOL_EXIT_FAIL;
    for (size_t k = 1; k < c->nclasses; k++)
        if (sz[k] < sz[worst])
            worst = k;
    int r = 0;
    if (sz[worst] < 2) /* no --train leaves one to test and one to train */
        r = usage_error("--train", "class '%s' has 1 shape: --protocol split needs at least 2 in every class (one "
                        "to train, one to test)", c->classes[worst]);
    else if (train >= sz[worst])
        r = usage_error("--train", "%zu training shapes per class leave none to test in class '%s' (%zu shapes); "
                        "use --train %zu or less",
                        train, c->classes[worst], sz[worst], sz[worst] - 1);
    free(sz);
    return r;
}

/* What the protocol needs of the collection, checked before any shape is prepared. */
static int check_collection(const opts *o, const collection *c)
{
    const char *in = o->pos[0];
    if (collection_out_not_input("--plot", o->plot, index_file_is(in) ? NULL : c, &in, 1) != 0)
        return TOOL_EXIT_FAIL;
    if (c->n < 2) {
        tool_error(o->pos[0], "eval needs at least 2 shapes, found %zu", c->n);
        return TOOL_EXIT_FAIL;
    }
    if (o->protocol_id == PROTO_SPLIT)
        return split_check(c, o->train);
    if (o->protocol_id != PROTO_GROUPS)
        return 0;
    if (c->ngroups == 0) {
        tool_error(o->pos[0], "--protocol groups needs a manifest with a 'group' column (file, class, group)");
        return TOOL_EXIT_FAIL;
    }
    if (c->ngroups < 2) {
        tool_error(o->pos[0], "--protocol groups needs at least 2 groups, found 1 ('%s')", c->groups[0]);
        return TOOL_EXIT_FAIL;
    }
    return 0;
}

int cmd_eval(opts *o)
{
    const char *cpath = o->pos[0];
    int pr = o->protocol_id;
    eval_scores s;
    memset(&s, 0, sizeof s);
    s.want_be = pr == PROTO_ALL || pr == PROTO_BULLSEYE;
    s.want_tk = pr == PROTO_ALL || pr == PROTO_TOPK;
    s.want_nn = pr == PROTO_ALL || pr == PROTO_NN;
    s.want_split = pr == PROTO_SPLIT;
    s.want_groups = pr == PROTO_GROUPS;
    s.be = s.nn = NAN;
    s.t0 = now_seconds();
    retrieval_tracing();
    amscr_params *p = NULL;
    collection c;
    amscr_db *db = NULL;
    double *d = NULL;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);
    memset(&c, 0, sizeof c);
    if (o->train && pr != PROTO_SPLIT)
        return usage_error("--train", "only with --protocol split");
    if (pr == PROTO_SPLIT && o->train == 0)
        return usage_error("--protocol", "split needs --train K (training shapes per class)");
    int r = open_collection_db(o, cpath, check_collection, &p, &c, &db);
    if (r != 0) {
        ret = r;
        goto done;
    }
    s.t1 = now_seconds();
    if ((pr == PROTO_GROUPS ? heldout_matrix(db, &c, cpath, &d) : compute_matrix(db, cpath, &d)) != 0)
        goto done;
    s.t2 = now_seconds();
    s.ranks = o->ranks ? o->ranks : TOOL_RANKS_DEFAULT;
    if (s.ranks > c.n - 1)
        s.ranks = c.n - 1;
    if (compute_scores(d, &c, o, cpath, &s) != 0)
        goto done;
    if (o->plot && draw_plot(o, d, &c, &s) != 0)
        goto done;
    s.secs = now_seconds() - s.t0;
    if (o->json)
        format_json(&b, o, &c, p, &s);
    else
        format_text(&b, o, &c, p, &s);
    if (sb_write_stdout(&b) == 0)
        ret = TOOL_EXIT_OK;
done:
    sb_free(&b);
    free(d);
    free(s.counts);
    free(s.cls_nn);
    free(s.cls_be);
    free(s.sizes);
    free(s.labels);
    free(s.split_acc);
    free(s.split_cls);
    free(s.groups_grp);
    free(s.groups_cls);
    amscr_db_free(db);
    collection_free(&c);
    amscr_params_free(p);
    return ret;
}
