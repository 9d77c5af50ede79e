/* cmd_eval.c — `amscr eval COLLECTION`: retrieval scores of a labelled collection. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "amscr.h"
#include "cli.h"
#include "collection.h"
#include "json.h"
#include "names.h"
#include "params.h"
#include "retrieval.h"

/* The scores the protocol asks for, and the times of the steps. */
typedef struct eval_scores {
    int want_be, want_tk, want_nn;
    double be, nn;
    size_t *counts; /* top-k table, ranks entries */
    size_t ranks;
    double t0, t1, t2, secs; /* start, db prepared, matrix done; total seconds */
} eval_scores;

static int compute_scores(const double *d, const collection *c, const char *cpath, eval_scores *s)
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
    return 0;
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
    sb_printf(b, "seconds     %.2f  (prepare %.2f, matrix %.2f: %.0f pairs/s)\n", s->secs, s->t1 - s->t0, tm,
              s->t2 > s->t1 ? (double)n * (double)(n - 1) / tm : 0.0);
}

int cmd_eval(opts *o)
{
    const char *cpath = o->pos[0];
    int pr = o->protocol_id;
    eval_scores s = {pr == PROTO_ALL || pr == PROTO_BULLSEYE, pr == PROTO_ALL || pr == PROTO_TOPK,
                     pr == PROTO_ALL || pr == PROTO_NN, NAN, NAN, NULL, 0, now_seconds(), 0, 0, 0};
    amscr_params *p = NULL;
    collection c;
    amscr_db *db = NULL;
    double *d = NULL;
    int ret = TOOL_EXIT_FAIL;
    sbuf b;
    sb_init(&b);
    memset(&c, 0, sizeof c);
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
    s.t1 = now_seconds();
    if (compute_matrix(db, cpath, &d) != 0)
        goto done;
    s.t2 = now_seconds();
    s.ranks = o->ranks ? o->ranks : TOOL_RANKS_DEFAULT;
    if (s.ranks > c.n - 1)
        s.ranks = c.n - 1;
    if (compute_scores(d, &c, cpath, &s) != 0)
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
    amscr_db_free(db);
    collection_free(&c);
    amscr_params_free(p);
    return ret;
}
