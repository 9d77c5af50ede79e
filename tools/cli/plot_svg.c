/* plot_svg.c — the scale-selection plot of the amscr tool (draw.h): the residual of each scale
 * with the Bayes threshold, and the elbow curve, as a two-panel SVG. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "draw.h"
#include "raster.h"
#include "util.h"

/* "Nice" tick step for a range. */
static double nice_step(double range, int target_ticks)
{
    if (!(range > 0) || !isfinite(range))
        return 1.0;
    double raw = range / target_ticks;
    double mag = pow(10.0, floor(log10(raw)));
    double f = raw / mag;
    double nf = f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10;
    return nf * mag;
}

typedef struct panel {
    double x, y, w, h;    /* plotting area in SVG units */
    double x0, x1, y0, y1; /* data range */
} panel;

static double px_of(const panel *P, double v) { return P->x + (v - P->x0) / (P->x1 - P->x0) * P->w; }
static double py_of(const panel *P, double v) { return P->y + P->h - (v - P->y0) / (P->y1 - P->y0) * P->h; }

static void svg_axes(sbuf *b, const panel *P, const char *title, const char *xlabel, const char *ylabel)
{
    sb_printf(b, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#444\"/>\n",
              P->x, P->y, P->w, P->h);
    double step = nice_step(P->y1 - P->y0, 5);
    char buf[32];
    for (double v = ceil(P->y0 / step) * step; v <= P->y1 + 1e-9 * step; v += step) {
        double y = py_of(P, v);
        sb_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", P->x, y,
                  P->x + P->w, y);
        double vv = fabs(v) < 1e-9 * step ? 0.0 : v;
        int dec = (int)-floor(log10(step) + 1e-9);
        if (dec >= 0 && dec <= 8 && fabs(vv) < 1e5)
            snprintf(buf, sizeof buf, "%.*f", dec, vv);
        else if (dec < 0 && fabs(vv) < 1e9)
            snprintf(buf, sizeof buf, "%.0f", vv);
        else
            snprintf(buf, sizeof buf, "%.3g", vv);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" font-size=\"11\">%s</text>\n", P->x - 5,
                  y + 4, buf);
    }
    sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"14\" font-weight=\"bold\">",
              P->x + P->w / 2, P->y - 12);
    svg_escape(b, title);
    sb_puts(b, "</text>\n");
    sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"12\">", P->x + P->w / 2,
              P->y + P->h + 36);
    svg_escape(b, xlabel);
    sb_puts(b, "</text>\n");
    sb_printf(b,
              "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"12\" "
              "transform=\"rotate(-90 %.1f %.1f)\">",
              P->x - 74, P->y + P->h / 2, P->x - 74, P->y + P->h / 2);
    svg_escape(b, ylabel);
    sb_puts(b, "</text>\n");
}

/* The data range of the residual panel: the residuals and the threshold (when drawn), padded;
 * zero-based only when they spread widely. */
static void residual_range(const plot_input *in, int thr_drawn, panel *P)
{
    double ymin = INFINITY, ymax = -INFINITY;
    for (size_t k = 0; k < in->p; k++)
        if (isfinite(in->residuals[k])) {
            if (in->residuals[k] > ymax) ymax = in->residuals[k];
            if (in->residuals[k] < ymin) ymin = in->residuals[k];
        }
    if (thr_drawn) {
        if (in->threshold > ymax) ymax = in->threshold;
        if (in->threshold < ymin) ymin = in->threshold;
    }
    if (!(ymax >= ymin)) {
        ymin = 0;
        ymax = 1;
    }
    if (ymax - ymin <= 1e-12 * fabs(ymax)) {
        double h = ymax != 0 ? 0.05 * fabs(ymax) : 1.0;
        ymin -= h;
        ymax += h;
    }
    double pad = 0.08 * (ymax - ymin);
    P->y0 = ymin - pad;
    P->y1 = ymax + pad;
    if (P->y0 < 0 || ymin < 0.25 * ymax)
        P->y0 = ymin >= 0 ? 0 : P->y0;
    if (in->p <= 1) {
        P->x0 = -1;
        P->x1 = 1;
    }
}

/* Panel 1: the residual per scale, kept scales filled, the Bayes threshold dashed. */
static void residual_panel(sbuf *b, const plot_input *in)
{
    panel P = {104, 70, 356, 250, -0.5, (double)in->p - 0.5, 0, 1};
    int thr_drawn = isfinite(in->threshold) && in->threshold >= 0;
    char buf[32];
    residual_range(in, thr_drawn, &P);
    svg_axes(b, &P, "Residual per scale (eq. 13)", "scale sigma_k (samples)", "residual L2_k");
    for (size_t k = 0; k < in->p; k++) {
        double x = px_of(&P, (double)k);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"11\">%s</text>\n", x,
                  P.y + P.h + 16, fmt_num(buf, in->scales[k]));
    }
    if (in->p > 1) {
        sb_puts(b, "<polyline fill=\"none\" stroke=\"#888\" stroke-width=\"1.5\" points=\"");
        for (size_t k = 0; k < in->p; k++)
            sb_printf(b, "%s%.1f,%.1f", k ? " " : "", px_of(&P, (double)k),
                      py_of(&P, isfinite(in->residuals[k]) ? in->residuals[k] : 0));
        sb_puts(b, "\"/>\n");
    }
    if (thr_drawn) {
        double y = py_of(&P, in->threshold);
        sb_printf(b,
                  "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#d62728\" stroke-width=\"1.5\" "
                  "stroke-dasharray=\"6 4\"/>\n",
                  P.x, y, P.x + P.w, y);
    } else {
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\" fill=\"#d62728\" font-size=\"11\">no "
                      "threshold: every scale kept</text>\n",
                  P.x + P.w - 4, P.y + 14);
    }
    for (size_t k = 0; k < in->p; k++) {
        double x = px_of(&P, (double)k), y = py_of(&P, isfinite(in->residuals[k]) ? in->residuals[k] : 0);
        if (in->kept[k])
            sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"#2ca02c\" stroke=\"#1b6e1b\"/>\n", x, y);
        else
            sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"white\" stroke=\"#777\" "
                          "stroke-width=\"1.5\"/>\n",
                      x, y);
    }
    /* legend of panel 1 */
    double lx = P.x - 16, ly = P.y + P.h + 52;
    sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"#2ca02c\" stroke=\"#1b6e1b\"/>"
                  "<text x=\"%.1f\" y=\"%.1f\">kept scale</text>\n",
              lx, ly, lx + 10, ly + 4);
    sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"white\" stroke=\"#777\" stroke-width=\"1.5\"/>"
                  "<text x=\"%.1f\" y=\"%.1f\">dropped scale</text>\n",
              lx + 110, ly, lx + 120, ly + 4);
    sb_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#d62728\" stroke-width=\"1.5\" "
                  "stroke-dasharray=\"6 4\"/><text x=\"%.1f\" y=\"%.1f\">Bayes threshold s0%s%s</text>\n",
              lx + 230, ly, lx + 260, ly, lx + 266, ly + 4, thr_drawn ? " = " : "",
              thr_drawn ? fmt_num(buf, in->threshold) : "");

}

/* Panel 2: the elbow curve SSE(K), the chosen K marked. */
static void elbow_panel(sbuf *b, const plot_input *in)
{
    panel Q = {560, 70, 360, 250, 0.5, (double)in->kmax + 0.5, 0, 1};
    int have_sse = 0;
    double smax = 0;
    for (size_t k = 0; in->sse && k < in->kmax; k++) {
        if (isfinite(in->sse[k]) && in->sse[k] > smax)
            smax = in->sse[k];
        if (in->sse[k] != 0)
            have_sse = 1;
    }
    if (in->kmax == 0) {
        Q.x0 = 0.5;
        Q.x1 = 1.5;
    }
    Q.y1 = smax > 0 ? smax * 1.1 : 1;
    svg_axes(b, &Q, "Elbow: K-means SSE(K) (eq. 14)", "number of classes K", "SSE(K)");
    for (size_t k = 1; k <= in->kmax; k++)
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" font-size=\"11\">%zu</text>\n",
                  px_of(&Q, (double)k), Q.y + Q.h + 16, k);
    if (!have_sse || in->kmax == 0) {
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\" fill=\"#555\">no elbow: this method "
                      "does not select scales by K-means</text>\n",
                  Q.x + Q.w / 2, Q.y + Q.h / 2);
    } else {
        if (in->kmax > 1) {
            sb_printf(b,
                      "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#aaa\" stroke-dasharray=\"4 4\"/>\n",
                      px_of(&Q, 1), py_of(&Q, in->sse[0]), px_of(&Q, (double)in->kmax),
                      py_of(&Q, in->sse[in->kmax - 1]));
            sb_puts(b, "<polyline fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" points=\"");
            for (size_t k = 0; k < in->kmax; k++)
                sb_printf(b, "%s%.1f,%.1f", k ? " " : "", px_of(&Q, (double)(k + 1)), py_of(&Q, in->sse[k]));
            sb_puts(b, "\"/>\n");
        }
        for (size_t k = 0; k < in->kmax; k++) {
            double x = px_of(&Q, (double)(k + 1)), y = py_of(&Q, in->sse[k]);
            if (k + 1 == in->k)
                sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"7\" fill=\"#d62728\"/>"
                              "<text x=\"%.1f\" y=\"%.1f\" fill=\"#d62728\">K* = %zu</text>\n",
                          x, y, x + 10, y - 10, in->k);
            else
                sb_printf(b, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\" fill=\"#1f77b4\"/>\n", x, y);
        }
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\">dashed: chord from K = 1 to K = %zu; K* farthest below it</text>\n",
                  Q.x + 8, Q.y + Q.h + 70, in->kmax);
    }
}

int draw_plot_svg(const char *path, const plot_input *in)
{
    sbuf b;
    sb_init(&b);
    const int W = 960, H = 400;
    sb_printf(&b,
              "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
              "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
              "font-family=\"sans-serif\" font-size=\"12\">\n"
              "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
              W, H, W, H);
    if (in->title) {
        sb_printf(&b, "<text x=\"%d\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">", W / 2);
        svg_escape(&b, in->title);
        sb_puts(&b, "</text>\n");
    }

    residual_panel(&b, in);
    elbow_panel(&b, in);
    sb_puts(&b, "</svg>\n");
    int r = write_text_file(path, &b);
    sb_free(&b);
    return r;
}
