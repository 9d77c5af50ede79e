#include <amscr.h>
#include <stdio.h>

int main(int argc, char **argv) {                   /* usage: readme_example SRC.txt TGT.txt */
    amscr_contour *f = NULL, *h = NULL; amscr_result *r = NULL; double m[6];
    if (argc < 3 || amscr_contour_read_text(argv[1], &f) || amscr_contour_read_text(argv[2], &h) ||
        amscr_register_contours(NULL, f, h, &r) || amscr_result_affine(r, m)) {
        fprintf(stderr, "error: %s\n", amscr_last_error_detail()); return 1; }
    printf("A = [[%.4f, %.4f], [%.4f, %.4f]]  B = [%.3f, %.3f]  distance = %.3g\n",
           m[0], m[1], m[3], m[4], m[2], m[5], amscr_result_distance(r));
    amscr_result_free(r); amscr_contour_free(f); amscr_contour_free(h); return 0;
}
