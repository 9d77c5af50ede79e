/* eval_plot.c — the SVG of `amscr eval --plot` (see eval_plot.h). */
#include "eval_plot.h"

#include <math.h>
#include <stdio.h>

#include "raster.h"
#include "util.h"

enum { BAR_ROW = 16, LABEL_W = 150, LABEL_CHARS = 24, BAR_W = 300, PANEL_TOP = 60, PR_SIZE = 320, PR_LEFT = 560 };
static const char *const SERIES_COLOURS[3] = {"#1f77b4", "#ff7f0e", "#2ca02c"};

/* The left panel: a row per class, one bar per series, a 0..1 scale with ticks. */
static void bars_panel(sbuf *b, const eval_plot_input *in)
{
    double x0 = LABEL_W + 20, bh = (double)(BAR_ROW - 4) / (double)(in->nseries ? in->nseries : 1);
    double h = (double)in->nclasses * BAR_ROW;
    sb_printf(b, "<text x=\"%d\" y=\"%d\" font-size=\"14\" font-weight=\"bold\">score per class</text>\n", 20,
              PANEL_TOP - 24);
    for (int t = 0; t <= 4; t++) {
        double x = x0 + BAR_W * t / 4.0;
        sb_printf(b, "<line x1=\"%.1f\" y1=\"%d\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", x, PANEL_TOP, x,
                  PANEL_TOP + h);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" text-anchor=\"middle\">%.2g</text>\n", x,
                  PANEL_TOP + h + 14, t / 4.0);
    }
    for (size_t k = 0; k < in->nclasses; k++) {
        double y = PANEL_TOP + (double)k * BAR_ROW;
        sb_printf(b, "<text x=\"%d\" y=\"%.1f\" font-size=\"11\" text-anchor=\"end\">", LABEL_W + 14, y + 11);
        svg_escape_max(b, in->classes[k], LABEL_CHARS); /* anchored at its end: a longer one lost its start */
        sb_puts(b, "</text>\n");
        for (size_t s = 0; s < in->nseries; s++) {
            double v = in->series[s].value[k];
            if (!isfinite(v))
                continue;
            sb_printf(b, "<rect x=\"%.1f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"%s\"><title>", x0,
                      y + 2 + bh * (double)s, BAR_W * (v < 0 ? 0 : v > 1 ? 1 : v), bh, SERIES_COLOURS[s % 3]);
            svg_escape(b, in->classes[k]);
            sb_printf(b, " %s %.4f</title></rect>\n", in->series[s].name, v);
        }
    }
    for (size_t s = 0; s < in->nseries; s++) { /* legend */
        double y = PANEL_TOP + h + 30 + 16.0 * (double)s;
        sb_printf(b, "<rect x=\"%.1f\" y=\"%.1f\" width=\"12\" height=\"10\" fill=\"%s\"/>\n", x0, y,
                  SERIES_COLOURS[s % 3]);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"12\">", x0 + 18, y + 9);
        svg_escape(b, in->series[s].name);
        sb_puts(b, "</text>\n");
    }
}

/* The right panel: precision against recall, both 0..1. */
static void pr_panel(sbuf *b, const eval_plot_input *in)
{
    double x = PR_LEFT, y = PANEL_TOP, s = PR_SIZE;
    sb_printf(b, "<text x=\"%.1f\" y=\"%d\" font-size=\"14\" font-weight=\"bold\">precision-recall</text>\n", x,
              PANEL_TOP - 24);
    sb_printf(b, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"none\" stroke=\"#444\"/>\n", x,
              y, s, s);
    for (int t = 0; t <= 5; t++) {
        double f = t / 5.0;
        sb_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#eee\"/>\n", x + s * f, y,
                  x + s * f, y + s);
        sb_printf(b, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#eee\"/>\n", x, y + s * f,
                  x + s, y + s * f);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" text-anchor=\"middle\">%.1f</text>\n",
                  x + s * f, y + s + 14, f);
        sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"11\" text-anchor=\"end\">%.1f</text>\n", x - 4,
                  y + s - s * f + 4, f);
    }
    sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"12\" text-anchor=\"middle\">recall</text>\n", x + s / 2,
              y + s + 32);
    sb_printf(b, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"12\" text-anchor=\"middle\" "
              "transform=\"rotate(-90 %.1f %.1f)\">precision</text>\n", x - 34, y + s / 2, x - 34, y + s / 2);
    sb_puts(b, "<polyline id=\"pr\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"2\" points=\"");
    for (size_t i = 0; i < in->npr; i++)
        sb_printf(b, "%s%.2f,%.2f", i ? " " : "", x + s * in->recall[i], y + s - s * in->precision[i]);
    sb_puts(b, "\"/>\n");
}

int draw_eval_plot(const char *path, const eval_plot_input *in)
{
    int h = PANEL_TOP + (int)in->nclasses * BAR_ROW + 40 + 16 * (int)in->nseries + 20;
    if (h < PANEL_TOP + PR_SIZE + 60)
        h = PANEL_TOP + PR_SIZE + 60;
    int w = PR_LEFT + PR_SIZE + 30;
    sbuf b;
    sb_init(&b);
    sb_printf(&b,
              "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
              "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\" "
              "font-family=\"sans-serif\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
              "<text x=\"20\" y=\"20\" font-size=\"13\">",
              w, h, w, h);
    svg_escape(&b, in->title);
    sb_puts(&b, "</text>\n");
    bars_panel(&b, in);
    if (in->npr > 0)
        pr_panel(&b, in);
    sb_puts(&b, "</svg>\n");
    int r = write_text_file(path, &b);
    sb_free(&b);
    return r;
}
