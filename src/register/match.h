/* match.h — internals of the registration engine (never installed): the workspace, one match
 * and the stages of docs/method.md §12, one file each, in pipeline order:
 *   shape/descriptor.c  (per shape, once) validate, orient, parametrize, sample, whiten, smooth
 *   shape/despike.c     (per shape, once) isolated stray points dropped before parametrizing
 *   register.c          the public entry points: check the pair, run the stages below, top-down
 *   stages.c            the stage table of amscr_register: each stage's name, function and
 *                       when it runs, in pipeline order (the list below and amscr_result_stage)
 *   spectral.c          closed curves' cross sums at a continuous shift, for the two below
 *   shift_search.c      spectral start-point search: candidates and their one ranking rule
 *   method.c            the method at one start point: per-scale solves, residuals, stacked solve
 *   scale_select.c      which scales enter the stacked solve (all, finest, EM + Bayes threshold)
 *   group_fit.c         the least-squares map of one system within the invariance group; the distance
 *   refine.c            trimmed closest-point (point-to-line) refinement
 *   partial.c           partial matching: an open fragment placed on the closed target (no shift search)
 *   recover.c           part of the target missing: source fragments placed as further starts
 *   final_solve.c       the reported solve by LAPACKE QR; the distance
 *   polish.c            the reported map polished on the input points (amscr_register only)
 *   polish_rank.c       the starts the polish tries, their ambiguity and ranking in the match
 *   nearest.c           closest points on the input polylines, for the polish (nearest.h)
 *   ordered.c           the polish's order stage: a noisy curve's point order (ordered.h)
 *   even.c              the polish's even-spacing stage: points taken evenly along it (even.h)
 *   alternatives.c      the distinct maps that fit about as well as the chosen one
 *   correspond.c        inliers, the part covered, dense correspondences
 *   pixel_grid.c        a small binary image's target or source: its tracing's bias simulated (register.c
 *                       finds the map again)
 *   precision.c         the gap between two maps; the standard error: a jackknife of the fit
 *   check.c             the overlap, the symmetry test, the forward-backward check (register.c runs them)
 *   result.c            the result object, its getters and the confidence
 * and workspace.c, the caller-owned scratch of all of the above. */
#ifndef AMSCR_MATCH_H
#define AMSCR_MATCH_H

#include "fft.h"
#include "internal.h"

/* The target polygon the refinement takes closest points on: the N samples densified 4x by
 * Catmull-Rom interpolation (through the samples, following the curvature), so that chords of
 * a coarse polygon do not bias the fit. */
#define AMSCR__DENSE 4

/* Candidate start shifts per orientation: a shape's criterion rarely has more than a few deep
 * minima (symmetries); the lowest three, which keep the right one among them at a small cost, are
 * the reported map's pool. With refinement on (the ranked search), when those three are distinct
 * maps that score alike (in the search's ranking or the polish's), the further minima are ranked
 * too (shift_search.c), so that a shape with more symmetries than three (a square's four quarter
 * turns, a regular star's fifths) lists each as an alternative — up to AMSCR__CANDIDATES_MAX per
 * orientation (a 12-fold symmetry). One of them becomes the reported map only when it scores
 * clearly better than the best of the lowest three: its cost below AMSCR__HELD_WIN times theirs (a near-symmetric shape whose right turn the criterion ranks
 * fourth or later, measured on bench/registration_heldout.py --sets). */
#define AMSCR__CANDIDATES 3
#define AMSCR__CANDIDATES_MAX 12
#define AMSCR__HELD_WIN 0.9

/* Per-stage timing, compiled only into the benchmark's copy of the library
 * (-DAMSCR_STAGE_TIMING): the product's hot path has no clock calls. */
#ifdef AMSCR_STAGE_TIMING
double amscr__stage_now(void);
#define STAGE_T0 double stage_t = amscr__stage_now()
#define STAGE_MARK(ws, i)                                                                                      \
    do {                                                                                                       \
        double stage_t1 = amscr__stage_now();                                                                  \
        (ws)->stage[i] += stage_t1 - stage_t;                                                                  \
        stage_t = stage_t1;                                                                                    \
    } while (0)
#else
#define STAGE_T0 ((void)0)
#define STAGE_MARK(ws, i) ((void)0)
#endif

struct amscr_workspace {
    size_t n, p;
    amscr__fft_plan plan;
    double *z;       /* 4N: two complex arrays */
    double *crit;    /* N */
    double *P;       /* 8 (N/2+1): products H_i conj(F_j) for ij = xx, xy, yx, yy (complex) */
    double *q;       /* 4 (N/2+1): their real parts at the current fractional shift */
    double *curve;   /* 2N: a shifted target curve for the reported solve */
    double *scratch; /* selection scratch */
    size_t scratch_cap;
    /* QR of the final stacked system */
    double *qa, *qb, *qw;
    int *qi;
    size_t qcap;
    /* refinement in the aligned frame: closest-point pairs and residuals */
    double *rbuf;
    size_t rcap;
#ifdef AMSCR_STAGE_TIMING
    double stage[4]; /* shift search, per-scale solves, selection, final solve */
#endif
};

typedef struct {
    double X[6]; /* h ≈ A f + B in the normalized frames: {a11, a12, b1, a21, a22, b2} */
    double dist;
    size_t shift;
    double fshift; /* continuous shift (closed curves) */
    double rcut;   /* refined: the trimming cut-off of the closest-point pairs in ws->rbuf */
    double rcost;  /* refinement on: the trimmed closest-point cost of the final map */
    int refined;   /* the refinement replaced the method's solution */
    int reflected;
    size_t p;
    double resid[AMSCR__MAX_SCALES];
    int kept[AMSCR__MAX_SCALES];
    size_t nkept;
    size_t k;
    double sse[AMSCR__KMAX];
    size_t nsse;
    double w[AMSCR__KMAX], mu[AMSCR__KMAX], var[AMSCR__KMAX];
    size_t ncomp;
    double threshold;
    /* confidence of the match (see amscr_result_ambiguity / _inlier_fraction) */
    double ambiguity;
    /* the search's scored start candidates (registration with refinement; else ncand 0) */
    double cand[2 * AMSCR__CANDIDATES_MAX][6];
    int cand_o[2 * AMSCR__CANDIDATES_MAX]; /* their orientations */
    size_t ncand;
    size_t ncand_base; /* the first ncand_base of cand may win (the rest: further minima, AMSCR__HELD_WIN) */
    /* the last ranking of distinct starts (the search's, or the polish's when it re-ranked):
     * their maps (normalized frames), orientations, ranking costs and the winner (nrank 0:
     * none); the first rank_nbase are the lowest minima (they may win), further minima follow */
    double rank_X[1 + 2 * AMSCR__CANDIDATES_MAX][6];
    int rank_o[1 + 2 * AMSCR__CANDIDATES_MAX];
    double rank_cost[1 + 2 * AMSCR__CANDIDATES_MAX];
    size_t nrank, rank_best, rank_nbase;
} match_t;

/* Most maps a result lists as alternatives: the chosen one and every distinct ranked start. */
#define AMSCR__MAX_ALTERNATIVES (1 + 2 * AMSCR__CANDIDATES_MAX)

struct amscr_result {
    amscr_method method;
    match_t m;
    double affine_in[6];
    double affine_norm[6];
    /* dense correspondences (see correspond.c), malloc'ed, n samples */
    size_t ncorr;
    double *corr;  /* 5n: source xy (input), target parameter, target xy (input) */
    double inlier; /* inlier fraction */
    double part[2];
    double overlap; /* IoU of the two contours as regions under the map (check.c); NaN: not closed */
    double fb;      /* forward-backward error (check.c); NaN when the way back did not run */
    double amb_conv; /* the ambiguity near a symmetry of the source (check.c); NaN: not run */
    double se;      /* the map's standard error (precision.c); NaN: not measured */
    int backward;   /* this result is a forward-backward check's way back: no check of its own */
    unsigned char ran[AMSCR__NUM_STAGES]; /* which stages ran (stages.c) */
    /* the distinct maps that fit about as well (alternatives.c), input coordinates; 0 the chosen */
    double alt[AMSCR__MAX_ALTERNATIVES][6];
    double alt_cost[AMSCR__MAX_ALTERNATIVES];
    size_t nalt;
};

/* ---- workspace.c ---- */
void amscr__ws_release(amscr_workspace *ws);
/* Room for the search and the method at n samples and p scales. */
amscr_status amscr__ws_reserve(amscr_workspace *ws, size_t n, size_t p);
/* Room for a stacked QR of `rows` rows (3 unknowns, 2 right-hand sides). */
amscr_status amscr__ws_reserve_qr(amscr_workspace *ws, size_t rows);
/* Room for the refinement's closest-point buffers at n samples. */
amscr_status amscr__ws_reserve_refine(amscr_workspace *ws, size_t n);

/* ---- group_fit.c ---- */
/* Target index of source sample a under (shift s, orientation o): o = 0 -> (a+s) mod n;
 * o = 1 (reversed target, closed) -> -(a+s) mod n; open: o = 1 -> n-1-a. */
static inline size_t amscr__tgt_index(size_t a, size_t s, int o, int closed, size_t n)
{
    if (!closed)
        return o ? n - 1 - a : a;
    size_t b = a + s;
    if (b >= n)
        b -= n;
    return o ? (b == 0 ? 0 : n - b) : b;
}
/* Cross sums of one level at an integer shift: R = Σ h [f, 1]^T (2x3 row-major). */
void amscr__cross_sums(const double *f, const double *h, size_t n, size_t s, int o, int closed, double R[6]);
/* The least-squares map X of moments mom and cross sums R within the params' invariance
 * group (Minv: the inverse normal matrix when known, else NULL). Returns 0 when singular. */
int amscr__fit_x(const amscr_params *prm, const double mom[6], const double *Minv, const double R[6], double X[6]);
/* Σ_a |X [f;1] - h|^2 from the moments of f, the cross sums R and |h|^2 (clamped at 0). */
double amscr__resid_sum(const double X[6], const double mom[6], const double R[6], double hn2);
/* The distance of map X with squared residual sum `sq` over n samples: (sq + penalty) / n. */
double amscr__distance_of(const amscr_params *prm, const double X[6], double sq, size_t n);

/* ---- scale_select.c ---- */
void amscr__select_scales(const amscr_params *prm, size_t finest, match_t *m, double *scratch);
/* Scratch (doubles) of the selection at p scales. */
size_t amscr__select_scratch(size_t p);

/* ---- spectral.c ---- */
/* The rotation recurrence e^{iθw} of the spectral sums is re-computed exactly every 256
 * frequencies (mask 255) so its rounding does not grow with N. */
#define AMSCR__REANCHOR 255
/* P_ij(w) = H_i(w) conj(F_j(w)) of orientation o into ws->P (closed curves). */
void amscr__spectral_prepare(const amscr_descriptor *f, const amscr_descriptor *h, int o, amscr_workspace *ws);
/* Cross sums R_0 (unsmoothed) .. R_p (scale k) at the continuous shift s from ws->P. */
void amscr__spectral_cross_sums(const amscr_descriptor *f, const amscr_descriptor *h, double s, amscr_workspace *ws,
                                double R[][6]);

/* ---- shift_search.c ---- */
/* The start-point search's outcome: the candidates, their scores and the winner. */
typedef struct {
    double s[2 * AMSCR__CANDIDATES_MAX]; /* continuous shift */
    int o[2 * AMSCR__CANDIDATES_MAX];    /* orientation */
    double X[2 * AMSCR__CANDIDATES_MAX][6], score[2 * AMSCR__CANDIDATES_MAX];
    double dist[2 * AMSCR__CANDIDATES_MAX]; /* the distance: the ranking's tie-break */
    size_t count, best;
    size_t nbase; /* the first nbase: the lowest minima, the winner's pool; then the further ones */
    int kind;       /* how the candidates were scored (shift_search.c) */
    int prepared_o; /* the orientation whose spectra ws->P holds */
    /* the further minima not ranked (integer shifts, orientations): their orientation's lowest
     * ones did not score alike in the search; the polish's ranking may ask for them
     * (amscr__search_held) */
    size_t held_i[2 * (AMSCR__CANDIDATES_MAX - AMSCR__CANDIDATES)];
    int held_o[2 * (AMSCR__CANDIDATES_MAX - AMSCR__CANDIDATES)];
    size_t nheld;
} amscr__search;
/* The start-point search of f -> h: every candidate scored by one ranking rule into *s. */
amscr_status amscr__search_starts(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                  amscr_workspace *ws, amscr__search *s);
/* The method and its whole refinement at the search's winner into m (with the ambiguity and
 * the ranked candidates). */
amscr_status amscr__method_at(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                              amscr_workspace *ws, amscr__search *s, match_t *m);
/* Whether the lowest minima of orientation o (among the first nbase of a ranking: maps X,
 * orientations ro, costs cost, winner best) are AMSCR__CANDIDATES distinct maps that all score
 * about as well as the winner, by the alternatives' tests: a shape with three or more
 * symmetries, which may have more (its further minima are then ranked too). */
/* Whether a further minimum of cost `cost` beats the best of the lowest minima (cost `best`):
 * AMSCR__HELD_WIN. */
int amscr__held_wins(double cost, double best);
int amscr__lowest_alike(const amscr_descriptor *f, double X[][6], const int *ro, const double *cost, size_t nbase,
                        size_t best, int o);
/* The further minima of orientation o the search held back, scored as the ranked ones were
 * (the method and a short refinement): their maps (normalized frames) into X, their count
 * into *out_n; they are no longer held. */
amscr_status amscr__search_held(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                amscr_workspace *ws, amscr__search *s, int o, double X[][6], size_t *out_n);
/* The best start point of f -> h (one ranking rule), run through the method and refined. */
amscr_status amscr__match_dir(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                              amscr_workspace *ws, match_t *m);

/* ---- method.c ---- */
/* The whole method at one (shift, orientation): fills m (normalized-frame solution by the
 * closed form). Closed curves: continuous shift s through the spectra in ws->P (prepared
 * for orientation o). Open curves: s is ignored (orientation only). */
void amscr__run_method(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h, double s, int o,
                       amscr_workspace *ws, match_t *m);

/* ---- refine.c ---- */
/* Refines m in place with at most `iters` closest-point iterations; sets m->rcost (and, when
 * a step was taken, m->X, m->dist, m->refined, m->rcut). */
amscr_status amscr__refine_match(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                 amscr_workspace *ws, match_t *m, unsigned iters);

/* ---- final_solve.c ---- */
/* The reported solve of m by LAPACKE QR (affine invariance): the stacked system of the kept
 * scales, or after refinement the kept closest-point pairs. */
amscr_status amscr__final_solve(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                amscr_workspace *ws, match_t *m);

/* ---- robust registration: robust, partial, confidence, correspondences ---- */
/* Exported pieces of refine.c: the closest point on a polygon within edges b0 ± w; Catmull-Rom
 * densification by AMSCR__DENSE. */
double amscr__closest_on_polygon(const double *H, size_t n, int closed, size_t b0, size_t w, double px, double py,
                                 double *qx, double *qy, size_t *seg);
/* The edges of closed polygon H (n vertices) into E (5n: their starts x, y, vectors x, y and
 * squared lengths, array by array), for amscr__closest_on_closed. */
void amscr__closed_edges(const double *H, size_t n, double *E);
/* amscr__closest_on_polygon of a closed polygon (edges E): the same result, faster. */
double amscr__closest_on_closed(const double *E, size_t n, size_t b0, size_t w, double px, double py, double *qx,
                                double *qy, size_t *seg);
size_t amscr__densify(const double *H, size_t n, int closed, double *out);
/* The trimmed point-to-line solve (affine invariance; the other groups: point-to-point) of the
 * pairs f_a -> q_a with r2_a <= cut, seg_a the dense target edge of q_a. Returns 0 if singular. */
int amscr__plane_solve(const amscr_params *prm, const double *f, const double *q, const double *r2,
                       const double *seg, const double *Hd, size_t nd, size_t n, double cut, double X[6]);
/* recover.c: re-examines a refined closed-curve map that leaves many source samples without a
 * target boundary near them (part of the target missing): fragments of the source placed by
 * partial matching as further starts, ranked by a two-way trimmed cost; ws->rbuf keeps the
 * winner's pairs. */
/* recover.c: whether m leaves enough source samples without a target boundary near them for
 * amscr__recover_missing to look further. */
int amscr__recover_applies(const amscr_descriptor *f, const amscr_descriptor *h, const amscr_workspace *ws,
                           const match_t *m);
amscr_status amscr__recover_missing(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                    amscr_workspace *ws, match_t *m);
/* recover.c: the adaptive trimmed closest-point refinement of m (global partners first) on a
 * closed target; ws->rbuf keeps the pairs. */
amscr_status amscr__refine_adaptive(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                    amscr_workspace *ws, match_t *m);
/* recover.c: each of the count maps X refined to convergence (the adaptive refinement, in place)
 * and scored by the recovery's two-way trimmed cost into cost. */
amscr_status amscr__rank_converged(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                   double X[][6], size_t count, double *cost);
/* A candidate map differing from the chosen one by more than this RMS displacement (10 % of
 * the normalized frame's RMS radius sqrt 2) is a different answer for the ambiguity. */
#define AMSCR__DISTINCT_GAP2 0.02
/* Cost differences below an RMS misfit of 0.5 % of the RMS radius are no evidence for one map
 * over another: the ambiguity compares (cost + floor) of the two. */
#define AMSCR__AMBIGUITY_FLOOR (0.005 * 0.005 * 2.0)

/* partial.c: source f an open fragment of the closed target h: the whole search and refinement
 * into m (refined; ws->rbuf holds the final closest-point pairs as after amscr__refine_match). */
amscr_status amscr__match_partial(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                  amscr_workspace *ws, match_t *m);
/* The same with the fragment's share of the target's affine length searched from phi_min up (a
 * caller that knows the fragment is long: fewer placements to try); either_way: the fragment's
 * points may run either way along the target (the caller's fragment; 0: a piece of a prepared
 * closed source, which runs the target's way). */
amscr_status amscr__match_partial_min(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                      double phi_min, int either_way, amscr_workspace *ws, match_t *m);

/* polish.c: m's map polished on the input points the descriptors kept (f->raw, h->raw; a closed
 * target, affine invariance): the chosen map and the search's other distinct candidates,
 * point-to-line both ways weighted by each curve's measured noise (partial: f an open fragment,
 * its points alone), ranked by a two-way trimmed cost; m->X, m->ambiguity and the ranking
 * (m->rank_*) updated when a polished map wins. *out: the polish's state for its order and
 * even-spacing steps (NULL when the fit did not finish; amscr__polish_end frees it). */
typedef struct amscr__polish_state amscr__polish_state;
amscr_status amscr__polish_fit(const amscr_descriptor *f, const amscr_descriptor *h, int partial, match_t *m,
                               amscr__polish_state **out);
/* Whether the match's ranking is the polish's (it re-ranked the search's distinct starts). */
int amscr__polish_reranked(const amscr__polish_state *ps);
/* The polish's ranking in m extended by further starts of orientation o (X, n, normalized
 * frames): each that differs from every ranked map polished as the ranked starts were and
 * appended; one clearly better than the winner (AMSCR__HELD_WIN) is polished on and becomes it
 * (m->X, the polish's map for its later steps); the ambiguity takes them in. AMSCR_E_NOMEM when out of memory. */
amscr_status amscr__polish_rank_more(amscr__polish_state *ps, double X[][6], size_t n, int o, match_t *m);
/* Whether the order and even-spacing steps apply to the polished map (markedly noisier points,
 * no gap, not partial). */
int amscr__polish_steps_apply(const amscr__polish_state *w);
/* The polished map refined by the order of the noisier curve's points (ordered.c), into m->X. */
amscr_status amscr__polish_order(amscr__polish_state *w, match_t *m);
/* The polished map refined by the even spacing of those points (even.c), into m->X. */
amscr_status amscr__polish_even(amscr__polish_state *w, match_t *m);
void amscr__polish_end(amscr__polish_state *w);
/* polish_rank.c: the polish's start maps into S (normalized frames) with their orientations so:
 * m's chosen map first, then, when the search could not tell its candidates apart, each
 * candidate that differs from all before; may_win[k]: start k may become the reported map by
 * the lowest cost (the search's further minima: only when clearly better, AMSCR__HELD_WIN).
 * Returns their count. */
size_t amscr__polish_starts(const amscr_descriptor *f, const match_t *m, double S[][6], int *so,
                            unsigned char *may_win);
/* The ambiguity of start `best` among the count polished starts S (costs cost): its cost over
 * the best cost of a clearly different map (1: as good; 0: none). */
double amscr__polished_ambiguity(const amscr_descriptor *f, double S[][6], const double *cost, size_t count,
                                 size_t best);
/* The polished starts (S, so, may_win, cost; best the winner) as m's ranking (m->rank_*). */
void amscr__polish_keep_ranking(double S[][6], const int *so, const unsigned char *may_win, const double *cost,
                                size_t count, size_t best, match_t *m);

/* stages.c: the stages of amscr_register on the checked pair, in pipeline order, into r (r->m,
 * r->ran). The caller fills the result's maps afterwards. */
amscr_status amscr__run_stages(const amscr_params *prm, const amscr_descriptor *src, const amscr_descriptor *tgt,
                               amscr_workspace *ws, amscr_result *r);
/* The name of stage i (< AMSCR__NUM_STAGES). */

/* alternatives.c: the result's alternatives (r->alt*, input coordinates) from the last ranking
 * of r->m: the chosen map first, then each distinct ranked map about as good, best first. */
void amscr__alternatives(const amscr_descriptor *f, const amscr_descriptor *h, amscr_result *r);
/* A ranked map whose (cost + floor) is within this factor of the chosen one's is "about as
 * good": listing one means an ambiguity of at least AMSCR__ALT_RATIO, so the confidence is at
 * most 1 - AMSCR__ALT_RATIO = 0.25, the benchmarks' limit of a confident answer. */
#define AMSCR__ALT_RATIO 0.75

/* correspond.c: the dense correspondences, inlier fraction and part of a finished result r of
 * f -> h (fills r->corr, r->ncorr, r->inlier, r->part). */
amscr_status amscr__correspond(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                               amscr_result *r);
/* The polish's adaptive trimming, which the standard error's jackknife shares: pairs within
 * AMSCR__TRIM_K times the median squared distance (5x the median distance: 3.4 sigma of
 * Gaussian noise, which keeps all but 0.07 % of noisy pairs — a tighter cut drops the tails that
 * carry a thin part's tip and lets the map slide; measured: 3x the distance 98.6 / 95.7 %, 5x
 * 100 / 97.1 % at 1 / 2 % noise). A missing run's pairs lie far beyond it. */
#define AMSCR__TRIM_K 25.0
/* precision.c: the block jackknife's standard error of a finished map of f into *out, in units
 * of the target's RMS radius, from nr (3n: each source sample's unit normal of the target's
 * boundary at its closest point and its residual along it; a zero normal: not used); NaN when
 * too few blocks or samples fix the map. Fails only for want of memory. */
amscr_status amscr__map_precision(const amscr_descriptor *f, const double *nr, size_t n, double *out);
/* precision.c: the mean squared displacement between the maps X1 and X2 over the samples of
 * f's base level. */
double amscr__map_gap2(const amscr_descriptor *f, const double X1[6], const double X2[6]);

/* pixel_grid.c (docs/method.md §11.7). The side the stage corrects for the pair f -> h under the
 * map X (the stage's condition): AMSCR__GRID_TARGET where h's input points lie on a binary image's
 * pixel lattice at a resolution where the tracing's bias counts, for h and for f under X;
 * else AMSCR__GRID_SOURCE where f's do, for f and for h under X's inverse, and h was traced from
 * an image too (on the lattice, or a pixel chain); else 0. */
enum { AMSCR__GRID_TARGET = 1, AMSCR__GRID_SOURCE = 2 };
int amscr__pixel_grid_side(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6]);
/* Whether d's input points lie on a binary image's pixel lattice (a sub-pixel tracing at half
 * level: each point one integer and one half-integer coordinate), whatever its size. */
int amscr__on_pixel_lattice(const amscr_descriptor *d);
/* Whether n points have an RMS radius within the pixel_grid stage's limit; whether f's input
 * points under the map X (onto h) have. */
int amscr__grid_small(const double *p, size_t n);
int amscr__grid_mapped_small(const amscr_descriptor *f, const amscr_descriptor *h, const double X[6]);
/* For the finished result r of f -> h and the side the stage corrects (the small shape: h for
 * AMSCR__GRID_TARGET, f for AMSCR__GRID_SOURCE): the pixels where the other shape under r's map
 * (its inverse for the source), rendered on the small shape's grid, differs from the small
 * shape's image (*out_differ), and the small shape corrected for the tracing's bias under that
 * map, prepared as it was (*out_d2, caller frees; NULL when nothing of the mapped shape survives
 * the grid). Fails only for want of memory. */
amscr_status amscr__grid_correct(const amscr_descriptor *f, const amscr_descriptor *h, const amscr_result *r, int side,
                                 amscr_descriptor **out_d2, size_t *out_differ);
/* r2, the registration of the pair with the small side replaced by d2 (f onto d2, or d2 onto h),
 * replaces r's map when its rendering differs from the small shape's image in fewer pixels than
 * first_differ: its map carried into the frames of f and h, its correspondences and standard
 * error measured on f and h (r keeps its stages' record). Fails only for want of memory. */
amscr_status amscr__grid_choose(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                                const amscr_descriptor *d2, int side, size_t first_differ, amscr_result *r,
                                amscr_result *r2);
/* pixel_chain.c (docs/method.md §11.7). Whether d's input points are a closed pixel chain (integer,
 * each 8-adjacent to the next); the image a chain h bounds traced again at sub-pixel, started
 * where h's samples start, prepared as h was (*out). register.c decides where (with
 * amscr__grid_small and amscr__grid_mapped_small). */
int amscr__is_pixel_chain(const amscr_descriptor *d);
amscr_status amscr__chain_retrace(const amscr_descriptor *h, amscr_descriptor **out);

/* check.c (docs/method.md §11.5). A confidence at or above this is a confident answer: the
 * limit the documentation tells callers to reject below (1 - AMSCR__ALT_RATIO). */
#define AMSCR__CONFIDENT 0.25
/* The way back runs for a confident map when less than this share of the shape (the smaller
 * of the inlier fraction and the overlap) agrees: a clean match never pays for it. */
#define AMSCR__CHECK_SHARE 0.85
/* The source's symmetries are tried as alternatives (check.c) for a confident map when less than
 * this share of the shape agrees: a bite of 0.3 x the radius leaves about 0.9 of it. */
#define AMSCR__SYM_SHARE 0.95
/* The forward-backward error that halves the confidence, in units of the RMS radius: half the
 * 2 % accuracy the benchmarks call a success (the two maps then disagree by that accuracy's
 * half each way). */
#define AMSCR__FB_SCALE 0.01
/* The intersection over union of the closed polygons P (n vertices) and Q (m), even-odd rule. */
amscr_status amscr__overlap(const double *P, size_t n, const double *Q, size_t m, double *out);
/* The overlap and, when it leaves doubt, the ambiguity near a symmetry and the forward-backward
 * error of a result r of f -> h that the stages finished (fills r->overlap, r->amb_conv, r->fb;
 * amscr_register runs it; the check's own registrations, r->backward, are not checked). */
amscr_status amscr__check(const amscr_params *prm, const amscr_descriptor *f, const amscr_descriptor *h,
                          amscr_workspace *ws, amscr_result *r);
/* result.c: (1 - max(ambiguity, the ambiguity near a symmetry)) x min(inlier fraction, overlap)
 * / (1 + (fb / AMSCR__FB_SCALE)^2) / (1 + (se / AMSCR__FB_SCALE)^2). */
double amscr__confidence(const amscr_result *r);

#endif
