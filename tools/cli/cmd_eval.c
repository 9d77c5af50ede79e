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
#include "json.h"
#include "names.h"
#include "cmd_params.h"
#include "protocols.h"
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
    int want_split, want_groups, want_nn_classes;
    split_result split;
    groups_result groups;
} eval_scores;

/* The per-class scores and the split / groups protocols. */
static int compute_protocols(const double *d, const collection *c, const opts *o, eval_scores *s)
{
    size_t nc = c->nclasses;
    if ((s->sizes = class_sizes(c)) == NULL)
        return -1;
    if (o->plot && !s->want_be && !s->want_nn && !s->want_split && !s->want_groups)
        s->want_nn_classes = 1; /* the plot's bars */
    if (s->want_nn_classes && (s->cls_nn = xmalloc_array(nc, sizeof(double))) == NULL)
        return -1;
    if (s->want_nn && (s->cls_nn = xmalloc_array(nc, sizeof(double))) == NULL)
        return -1;
    if (s->want_be && (s->cls_be = xmalloc_array(nc, sizeof(double))) == NULL)
        return -1;
    if ((s->cls_nn || s->cls_be) && per_class_loo(d, c, s->cls_nn, s->cls_be) != 0)
        return -1;
    if (s->want_split && protocol_split(d, c, o->train, o->splits, o->seed, &s->split) != 0)
        return -1;
    if (s->want_groups && protocol_groups(d, c, &s->groups) != 0)
        return -1;
    return 0;
}

static int compute_scores(const double *d, const collection *c, const opts *o, const char *cpath, eval_scores *s)
{
    size_t n = c->n;
    int32_t *labels = xmalloc_array(n, sizeof(int32_t));
    s->counts = xcalloc_array(s->ranks, sizeof(size_t));
    if (labels == NULL || s->counts == NULL) {
        free(labels);
        return -1;
    }
    for (size_t i = 0; i < n; i++)
        labels[i] = c->items[i].label;
    amscr_status st = AMSCR_OK;
    if (s->want_be)
        st = amscr_score_bullseye(d, n, labels, 0, &s->be);
    if (st == AMSCR_OK && s->want_tk)
        st = amscr_score_topk_table(d, n, labels, s->ranks, s->counts);
    if (st == AMSCR_OK && s->want_nn)
        st = amscr_score_nn_accuracy(d, n, labels, &s->nn);
    free(labels);
    if (st != AMSCR_OK) {
        tool_lib_error(cpath, st);
        return -1;
    }
    return compute_protocols(d, c, o, s);
}

/* ", \"split\": {...}, \"groups\": {...}, \"per_class\": [...]" as computed. */
static void json_protocols(sbuf *b, const collection *c, const eval_scores *s)
{
    const split_result *sp = &s->split;
    if (s->want_split) {
        sb_printf(b, ", \"split\": {\"train\": %zu, \"splits\": %zu, \"seed\": %llu, \"accuracy_mean\": ", sp->train,
                  sp->splits, sp->seed);
        sb_json_num(b, sp->mean);
        sb_puts(b, ", \"accuracy_std\": ");
        sb_json_num(b, sp->std);
        sb_puts(b, ", \"accuracies\": ");
        sb_json_nums(b, sp->acc, NULL, sp->splits);
        sb_puts(b, "}");
    }
    if (s->want_groups) {
        sb_printf(b, ", \"groups\": {\"n\": %zu, \"accuracy\": ", c->ngroups);
        sb_json_num(b, s->groups.acc);
        sb_puts(b, ", \"per_group\": [");
        for (size_t g = 0; g < c->ngroups; g++) {
            sb_puts(b, g ? ", {\"group\": " : "{\"group\": ");
            sb_json_str(b, c->groups[g]);
            sb_puts(b, ", \"accuracy\": ");
            sb_json_num(b, s->groups.grp[g]);
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
            sb_json_num(b, s->split.cls[k]);
        }
        if (s->want_groups) {
            sb_puts(b, ", \"groups_accuracy\": ");
            sb_json_num(b, s->groups.cls[k]);
        }
        sb_puts(b, "}");
    }
    sb_puts(b, "]");
}

static void format_json(sbuf *b, const opts *o, const collection *c, const amscr_params *p, const eval_scores *s)
{
    const char *proto = o->protocol ? o->protocol : "all";
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
    json_protocols(b, c, s);
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
    sb_printf(b, "collection  %s (%zu shapes, %zu classes)\n", o->pos[0], n, c->nclasses);
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
                  100.0 * s->split.mean, 100.0 * s->split.std, s->split.train, s->split.splits, s->split.seed);
    if (s->want_groups)
        sb_printf(b, "groups      %.2f %%  (1-NN, leave one of %zu groups out)\n", 100.0 * s->groups.acc, c->ngroups);
    sb_printf(b, "seconds     %.2f  (prepare %.2f, matrix %.2f: %.0f pairs/s)\n", s->secs, s->t1 - s->t0, tm,
              s->t2 > s->t1 ? (double)n * (double)(n - 1) / tm : 0.0);
}

enum { PR_LEVELS = 21 }; /* recall 0, 0.05, ..., 1 */

/* --plot: the per-class scores the protocol computed and the precision-recall curve. */
static int draw_plot(const opts *o, const double *d, const collection *c, const eval_scores *s)
{
    double rec[PR_LEVELS], prec[PR_LEVELS];
    score_series ser[4];
    size_t ns = 0;
    if (pr_curve(d, c, PR_LEVELS, prec) != 0)
        return -1;
    for (size_t l = 0; l < PR_LEVELS; l++)
        rec[l] = (double)l / (PR_LEVELS - 1);
    if (s->cls_nn)
        ser[ns++] = (score_series){"1-NN (leave one out)", s->cls_nn};
    if (s->cls_be)
        ser[ns++] = (score_series){"bull's eye", s->cls_be};
    if (s->want_split)
        ser[ns++] = (score_series){"1-NN (random split, mean)", s->split.cls};
    if (s->want_groups)
        ser[ns++] = (score_series){"1-NN (leave one group out)", s->groups.cls};
    char title[600];
    snprintf(title, sizeof title, "%s: %zu shapes, %zu classes", path_base(o->pos[0]), c->n, c->nclasses);
    eval_plot_input in = {title, c->classes, c->nclasses, ser, ns, rec, prec, PR_LEVELS};
    return draw_eval_plot(o->plot, &in);
}

/* What the protocol needs of the collection, checked before any shape is prepared. */
static int check_collection(const opts *o, const collection *c)
{
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
    if (compute_matrix(db, cpath, &d) != 0)
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
    split_result_free(&s.split);
    groups_result_free(&s.groups);
    amscr_db_free(db);
    collection_free(&c);
    amscr_params_free(p);
    return ret;
}
