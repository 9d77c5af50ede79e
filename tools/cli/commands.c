/* commands.c — the command table of the amscr tool (name, usage, help, handler) and the help
 * texts. The defaults the help names are read from the params the commands use (cmd_params.c) and
 * the names from the tables that the parser reads (names.c). */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "names.h"
#include "cmd_params.h"

static const char HELP_CONTOUR[] =
    "usage: amscr contour IMG [-o FILE] [--threshold N|auto] [--pixel-chain | --join]\n"
    "       amscr contour IMG --all [--json] [--min-area A] [-o FILE]\n"
    "\n"
    "Traces the outer boundary of the largest 8-connected foreground component of a\n"
    "PNG or PGM silhouette (holes and specks are ignored) and prints its points, one\n"
    "\"x y\" per line (x = column, y = row; pixel centres at integers), counter-clockwise\n"
    "in a y-up frame: the iso-line at the threshold's level (N + 0.5) by marching squares,\n"
    "to sub-pixel accuracy on grey and antialiased edges (a binary edge lies halfway\n"
    "between pixel centres). A text point list is passed through. -o writes to FILE\n"
    "(atomically).\n"
    "\n"
    "Images are converted to luminance (RGB: Rec. 601 weights; 16-bit samples are kept).\n"
    "With transparency, transparent pixels (alpha < 128) are background: an object cut\n"
    "out on a transparent background (most of the border transparent), or an image of\n"
    "one colour on one, is traced by its alpha channel.\n"
    "\n"
    "  -o, --output FILE       write the points to FILE instead of stdout\n"
    "  --threshold N|auto      pixels > N are 'on' (0..254, default 127, or 0 on an\n"
    "                          image of only 0s and 1s); auto = Otsu\n"
    "  --pixel-chain           the chain of boundary pixel centres instead of the iso-line\n"
    "  --join                  also the other large pieces near the largest (at least 5 %\n"
    "                          of its pixels, within its RMS radius, not in its holes),\n"
    "                          joined to its outline: the outline register, search,\n"
    "                          matrix, eval and index use\n"
    "  --all                   every contour: each 8-connected component's outer boundary\n"
    "                          (counter-clockwise) and each hole's (clockwise; with\n"
    "                          --pixel-chain through the hole's own pixels), with its\n"
    "                          parent (findContours' tree):\n"
    "                          a hole's parent is the component around it, a component's\n"
    "                          the hole it lies in. Text: '# contour I: outer|hole, parent\n"
    "                          P|-, area A, N points' then the points; blank lines between\n"
    "  --json                  (with --all) {image, count, contours: [{index, parent,\n"
    "                          hole, area, points}]}\n"
    "  --min-area A            (with --all) drop contours enclosing less than A pixels^2\n"
    "                          (and what lies inside them; default 10)\n";

static const char HELP_REGISTER[] =
    "usage: amscr register SRC TGT [options]\n"
    "\n"
    "Registers the source shape SRC onto the target TGT: the affine map (A, B) with\n"
    "TGT ~ A SRC + B in input coordinates, the affine-invariant distance, the residual\n"
    "of every scale, the scales kept by the selection, the start shift and whether a\n"
    "mirror match was used. Reflections are off by default here. An image's other\n"
    "large pieces near its largest component (5 % of its pixels, within its radius:\n"
    "a shape an occluder cut apart) are joined to its outline.\n"
    "\n"
    "  --json                  print one JSON object (keys A, B, distance, method,\n"
    "                          scales, residuals, kept, shift, reflected, k,\n"
    "                          threshold, sse, mixture, stages, alternatives, ...)\n"
    "  --overlay FILE          picture (.png or .svg): target, source before and after\n"
    "  --plot FILE             SVG: residual per scale with the Bayes threshold and the\n"
    "                          kept scales, and the elbow curve SSE(K) (not with\n"
    "                          --partial)\n"
    "  --partial               SRC is an open fragment of TGT's closed boundary: prints\n"
    "                          where on TGT it lies (start, end as fractions) instead of\n"
    "                          the scales (JSON residuals null)\n"
    "  --no-polish             skip the final fit on the input points themselves (it\n"
    "                          fits the noisier curve onto the cleaner one; on by default)\n"
    "  --stage NAME=on|off     switch an optional stage of the registration (repeatable):\n"
    "                          recovery, polish, pixel_grid (on by default); despike,\n"
    "                          order, even_spacing (off: for point lists with stray\n"
    "                          points or synthetic noise); the JSON's \"stages\" says\n"
    "                          which ran\n"
    "  --component N           use contour N of 'amscr contour --all' of each image\n"
    "                          (default: the largest outer contour); --min-area A as there\n"
    "\n"
    "Every result prints its confidence in [0, 1] ((1 - ambiguity) x the smaller of the\n"
    "inlier fraction and the overlap, lowered when a symmetric turn of the source fits as\n"
    "well or the target registered back onto the source does not undo the map; reject\n"
    "maps below 0.25) and, with --json, the overlap, the forward-backward error, the\n"
    "symmetry ambiguity and the matched target boundary\n"
    "parameter and point of every source sample (\"correspondences\").\n";

static const char HELP_SEARCH[] =
    "usage: amscr search QUERY COLLECTION [--top K] [--json] [--sheet FILE] [options]\n"
    "\n"
    "Ranks the shapes of COLLECTION (a folder, a manifest.tsv or an index) by their distance\n"
    "from QUERY and prints the K closest (default 10). Reflections are on by default.\n"
    "With re-ranking (the default) the distances are scores in [0, 1]: 0 for the\n"
    "query itself (when it is in the collection), below 0.5 for the shapes its\n"
    "nearest-neighbour context reaches (half of 1 - affinity / the row's largest),\n"
    "0.5 and above for the others, in the order of the fused distance. They rank;\n"
    "they are not a metric. --no-rerank prints the fused pairwise distances.\n"
    "\n"
    "  --top K                 how many results (default 10)\n"
    "  --json                  print one JSON object\n"
    "  --sheet FILE            contact sheet (.png or .svg): the query and its hits as\n"
    "                          thumbnails with rank, class and distance, each hit drawn\n"
    "                          (red) registered onto the query (grey)\n"
    "  --candidates M          against an index: match the M shapes whose signatures are\n"
    "                          nearest the query's (default 256; 0: every shape)\n"
    "  --component N           the query is contour N of 'amscr contour --all' (default:\n"
    "                          the largest outer contour); --min-area A as there\n";

static const char HELP_MATRIX[] =
    "usage: amscr matrix COLLECTION -o FILE [--names FILE] [options]\n"
    "\n"
    "Computes the n x n matrix D[i][j] = distance(shape i -> shape j) of a collection\n"
    "(rows in collection order: folder files sorted by name, or manifest order).\n"
    "FILE ending in .npy: NumPy .npy v1.0, little-endian float64, C order;\n"
    "otherwise (.tsv, .txt, - for stdout, or a device such as /dev/stdout): tab-separated\n"
    "text, one row per line, after a\n"
    "'#' comment line listing the files. Reflections are on by default.\n"
    "\n"
    "  -o, --output FILE       the matrix file (.tsv, .txt, .npy, - or /dev/...)\n"
    "  --names FILE            also write the row order: 'file<TAB>class' lines\n";

static const char HELP_EVAL[] =
    "usage: amscr eval COLLECTION [--protocol P] [--ranks K] [--json] [options]\n"
    "       amscr eval COLLECTION --protocol split --train K [--splits R] [--seed S]\n"
    "       amscr eval MANIFEST --protocol groups\n"
    "\n"
    "Retrieval scores of a labelled collection from its full distance matrix:\n"
    "  bullseye  bull's eye (MPEG-7): same-class shapes among the 2*Nc nearest,\n"
    "            query included, divided by the sum of class sizes\n"
    "  topk      for rank r = 1..K, how many queries have a same-class r-th nearest\n"
    "            neighbour (query excluded; Kimia tables)\n"
    "  nn        leave-one-out nearest-neighbour accuracy\n"
    "  all       all three (default)\n"
    "  split     per-class random split: K shapes of every class train, the rest are\n"
    "            classified by 1-NN; mean and spread over R splits (Swedish leaf: K 25)\n"
    "  groups    leave one group out: each group's shapes are classified by 1-NN\n"
    "            against the other groups (ETH-80: one object out), as new queries:\n"
    "            the group is out of the fusion and the re-ranking graph too; needs a\n"
    "            manifest with a 'group' column\n"
    "Classes: a folder's file names (\"bird-3.png\" -> bird) or the manifest's column.\n"
    "Reflections are on by default.\n"
    "\n"
    "  --protocol P            all | bullseye | topk | nn | split | groups\n"
    "  --train K               split: training shapes per class (each class needs > K)\n"
    "  --splits R              split: random splits averaged (default 10)\n"
    "  --seed S                split: seed of the random splits (default 1)\n"
    "  --ranks K               ranks of the top-k table (default 10; Kimia-216 uses 11;\n"
    "                          alias --topk-ranks)\n"
    "  --plot FILE             SVG: each class's scores as bars and the precision-recall\n"
    "                          curve (each shape querying the others)\n"
    "  --json                  one JSON object: n, classes, seconds and bullseye,\n"
    "                          topk, nn_accuracy, split, groups (those the protocol\n"
    "                          computes) and per_class: each class's scores\n";

static const char HELP_INDEX[] =
    "usage: amscr index COLLECTION -o FILE [--add] [options]\n"
    "\n"
    "Prepares every shape of COLLECTION (a folder or a manifest.tsv) once and writes the\n"
    "library's index (amscr_index_save; Python amscr.Index.load reads it): the prepared\n"
    "shapes with their file names, classes and groups, the shape and retrieval options\n"
    "(channel weight, affine share, re-ranking), a signature per shape and each shape's\n"
    "K nearest neighbours under the retrieval distance before re-ranking (--rerank K,\n"
    "default the preset's 8), so that search, matrix and eval take FILE wherever they\n"
    "take a collection with the same results, and one search never recomputes the\n"
    "collection's matrix (with a fused --channel-weight below 1 the query is scaled by\n"
    "the medians of the build). The file is versioned and checksummed, and written\n"
    "whole before it takes its name. Index files of amscr before 0.4 are refused:\n"
    "build them again.\n"
    "\n"
    "  -o, --output FILE       the index file\n"
    "  --candidates M          neighbours are sought among each shape's M nearest by\n"
    "                          signature only: for collections too\n"
    "                          large for every pair (default: 0, every pair, up to\n"
    "                          2000 shapes; 256 above)\n"
    "  --add                   append the shapes of COLLECTION to the index FILE: only the\n"
    "                          new shapes are prepared, and only pairs with a new shape\n"
    "                          matched; the shape and retrieval options (re-ranking\n"
    "                          included) must be the index's\n"
    "A command given an index uses the index's shape options; an option that differs from\n"
    "them is an error (rebuild the index); --rerank K[,ITER] and --no-rerank may differ\n"
    "(a search then ranks by the collection's matrix). search --candidates M (default\n"
    "256) matches the M shapes whose signatures are nearest the query's (0: every shape).\n"
    "An index does not keep the image-tracing options (--threshold, --pixel-chain): give\n"
    "a search of an image and --add the same ones as the build, or the images are traced\n"
    "differently (nothing checks them).\n";

static const tool_command COMMANDS[] = {
    {"contour", C_CONTOUR, 1, "IMG [-o FILE]", "trace a silhouette's outer contour, or every contour (--all)", HELP_CONTOUR, 0,
     cmd_contour},
    {"register", C_REGISTER, 2, "SRC TGT", "register SRC onto TGT: affine map, distance, scales", HELP_REGISTER,
     1, cmd_register},
    {"search", C_SEARCH, 2, "QUERY COLLECTION", "the shapes of a collection closest to QUERY", HELP_SEARCH, 1,
     cmd_search},
    {"matrix", C_MATRIX, 1, "COLLECTION -o FILE", "all-pairs distance matrix (.tsv or .npy)", HELP_MATRIX, 1,
     cmd_matrix},
    {"eval", C_EVAL, 1, "COLLECTION", "retrieval scores: bull's eye, top-k table, 1-NN", HELP_EVAL, 1, cmd_eval},
    {"index", C_INDEX, 1, "COLLECTION -o FILE", "prepare a collection once: an index file for search/matrix/eval",
     HELP_INDEX, 1, cmd_index},
};
enum { NUM_COMMANDS = sizeof COMMANDS / sizeof COMMANDS[0] };

const tool_command *command_find(const char *name)
{
    for (size_t i = 0; i < NUM_COMMANDS; i++)
        if (strcmp(name, COMMANDS[i].name) == 0)
            return &COMMANDS[i];
    return NULL;
}

const char *command_list(char *buf, size_t cap)
{
    size_t len = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < NUM_COMMANDS && len < cap; i++) {
        const char *sep = i == 0 ? "" : i + 1 == NUM_COMMANDS ? " or " : ", ";
        int w = snprintf(buf + len, cap - len, "%s%s", sep, COMMANDS[i].name);
        if (w < 0)
            break;
        len += (size_t)w;
    }
    return buf;
}

void print_main_help(void)
{
    printf("usage: amscr COMMAND [options] ...\n"
           "\n"
           "Affine multi-scale curve registration (AMSCR) of 2-D shapes.\n"
           "\n"
           "commands:\n");
    for (size_t i = 0; i < NUM_COMMANDS; i++) {
        char usage[64];
        snprintf(usage, sizeof usage, "%s %s", COMMANDS[i].name, COMMANDS[i].args);
        printf("  %-32s  %s\n", usage, COMMANDS[i].summary);
    }
    printf("\n"
           "  %-32s  print the library version\n"
           "  %-32s  options of a command\n"
           "\n"
           "Shapes are PNG or PGM silhouettes (detected by their magic bytes) or text point\n"
           "lists (one \"x y\" or \"x,y\" per line, '#' comments). A COLLECTION is a folder of\n"
           "shapes, a manifest.tsv with 'file' and 'class' columns, or an index (amscr index).\n"
           "Exit status: 0 success, 1 bad input or failure, 2 usage error.\n",
           "amscr --version", "amscr COMMAND --help");
}

/* The retrieval options of search/matrix/eval, their defaults read from ret. */
static void print_retrieval_options(const amscr_params *ret)
{
    printf("retrieval options (search/matrix/eval):\n"
           "  --channel-weight W      share of the shape channel (height functions matched by\n"
           "                          dynamic programming; tolerates articulation) against the\n"
           "                          AMSCR distance, 0..1 (default %g: the channel alone;\n"
           "                          0 with --open)\n"
           "  --affine-share S        share of the channel computed in the affine (whitened)\n"
           "                          frame, the rest in the similarity frame (default %g)\n"
           "  --affine-view F         a pair the affine frame alone finds F times nearer than\n"
           "                          the frames' mix is ranked by it (an affine view of a\n"
           "                          shape), F in 1..100; 0 = the mix for every pair\n"
           "                          (default %g)\n"
           "  --fast                  --affine-share 0: the channel in one frame, less time\n"
           "  --rerank K[,ITER]       contextual re-ranking: diffusion on the K-nearest-neighbour\n"
           "                          graph, ITER iterations (default %u,%u; ITER default %d)\n"
           "  --no-rerank             the fused pairwise distances\n"
           "  --inner-share S         share of the inner-distance graph in the re-ranking,\n"
           "                          0 <= S < 1 (default %g; 0 = one graph)\n"
           "  --inner-closing C       the inner distance's paths run inside the silhouette closed\n"
           "                          by a disk of radius C sqrt(area), 0..1 (default %g;\n"
           "                          0 = the silhouette as it is)\n"
           "  --paper                 the paper's method: the AMSCR distance alone, affine group,\n"
           "                          no refinement, no re-ranking (= --channel-weight 0\n"
           "                          --no-rerank --invariance affine --refine 0)\n",
           amscr_params_get_channel_weight(ret), amscr_params_get_channel_affine_share(ret),
           amscr_params_get_channel_affine_view(ret),
           amscr_params_get_rerank_k(ret), amscr_params_get_rerank_iterations(ret), TOOL_RERANK_ITERS,
           amscr_params_get_rerank_inner_share(ret), amscr_params_get_inner_closing(ret));
}

/* The image and shape options, their defaults read from reg (register's params) and ret
 * (search/matrix/eval's). */
static void print_shape_options(const amscr_params *reg, const amscr_params *ret)
{
    char methods[200], params[200], invs[200];
    const int none = -1; /* no "(default)" mark */
    printf("image options:\n"
           "  --threshold N|auto      pixels > N are 'on' (0..%d, default %d, or 0 on an image\n"
           "                          of only 0s and 1s: a 0/1 mask); auto = Otsu.\n"
           "                          Polarity is automatic: the image border is background.\n"
           "                          16-bit samples: the level N + 0.5 is scaled by 257.\n"
           "  --pixel-chain           trace the chain of boundary pixel centres instead of the\n"
           "                          sub-pixel iso-line at the threshold's level\n"
           "shape options:\n",
           TOOL_THRESHOLD_MAX, TOOL_THRESHOLD_DEFAULT);
    printf("  --method NAME           %s\n",
           name_choices(&METHOD_NAMES, (int)amscr_params_get_method(reg), methods, sizeof methods));
    printf("  --points N              samples per curve (default %zu for register, %zu otherwise)\n",
           amscr_params_get_num_samples(reg), amscr_params_get_num_samples(ret));
    printf("  --scales S1,S2,...      smoothing scales in samples (default: the library's)\n"
           "  --reflections           also try mirror matches (default: %s for register,\n"
           "  --no-reflections          %s for search, matrix and eval)\n"
           "  --open                  open curves (default closed)\n",
           amscr_params_get_reflections(reg) ? "on" : "off", amscr_params_get_reflections(ret) ? "on" : "off");
    printf("  --refine N              refinement iterations in the aligned frame (0..%d; default:\n"
           "                          %u for register, %u for search/matrix/eval; 0 is fastest)\n"
           "  --kmax K                largest K of the elbow (1..%d)\n"
           "  --symmetric             average the distance over both directions\n",
           TOOL_REFINE_MAX, amscr_params_get_refine(reg), amscr_params_get_refine(ret), TOOL_KMAX_MAX);
    printf("  --parametrization NAME  %s\n",
           name_choices(&PARAM_NAMES, (int)amscr_params_get_parametrization(reg), params, sizeof params));
    printf("  --invariance NAME       %s (default: %s for register,\n"
           "                          %s for search/matrix/eval)\n",
           name_choices(&INVARIANCE_NAMES, none, invs, sizeof invs),
           name_of(&INVARIANCE_NAMES, (int)amscr_params_get_invariance(reg)),
           name_of(&INVARIANCE_NAMES, (int)amscr_params_get_invariance(ret)));
    printf("  --threads N             threads for batch work (0 = all cores, the default)\n");
}

int print_command_help(const tool_command *c)
{
    fputs(c->help, stdout);
    if (!c->shape_options)
        return TOOL_EXIT_OK;
    amscr_params *reg = NULL, *ret = NULL;
    int r = default_params(1, &reg);
    if (r == 0)
        r = default_params(0, &ret);
    if (r == 0) {
        fputs("\n", stdout);
        print_shape_options(reg, ret);
        if (c->bit & C_RETRIEVAL)
            print_retrieval_options(ret);
    }
    amscr_params_free(reg);
    amscr_params_free(ret);
    return r;
}
