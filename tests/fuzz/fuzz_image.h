/* fuzz_image.h — the image decoders of the tool (tools/cli/image_pgm.c, image_png.c) on arbitrary bytes.
 *
 * tools/cli/image.h decodes files only (image_read(path, ...)), so each input is written to one
 * scratch file per process (in /dev/shm when it exists: no disk traffic) and decoded from
 * there: this is the tool's real entry point, format sniffing included. A decoded image is
 * then traced with amscr_contour_from_mask, as `amscr contour` does.
 * FUZZ_IMAGE_TEXT_OK is the image_read text_ok argument. */
#ifndef AMSCR_FUZZ_IMAGE_H
#define AMSCR_FUZZ_IMAGE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "amscr.h"
#include "fuzz_common.h"
#include "image.h"

static char fuzz_image_path[256];

static void fuzz_image_cleanup(void)
{
    if (fuzz_image_path[0])
        unlink(fuzz_image_path);
}

static const char *fuzz_image_write(const uint8_t *data, size_t size)
{
    if (!fuzz_image_path[0]) {
        const char *dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : (getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
        snprintf(fuzz_image_path, sizeof fuzz_image_path, "%s/amscr-fuzz-XXXXXX", dir);
        int fd = mkstemp(fuzz_image_path);
        if (fd < 0) {
            perror("mkstemp");
            abort();
        }
        close(fd);
        atexit(fuzz_image_cleanup);
    }
    FILE *f = fopen(fuzz_image_path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0) {
        perror(fuzz_image_path);
        abort();
    }
    return fuzz_image_path;
}

static int fuzz_image_one(const uint8_t *data, size_t size, int text_ok)
{
    const char *path = fuzz_image_write(data, size);
    tool_image img;
    tool_format fmt;
    int r = image_read(path, text_ok, &img, &fmt);
    if (r != 0) {
        FUZZ_CHECK(img.pix == NULL);
        return 0;
    }
    FUZZ_CHECK(img.pix != NULL && img.width >= 1 && img.height >= 1);
    FUZZ_CHECK(img.width <= AMSCR_MAX_IMAGE_SIDE && img.height <= AMSCR_MAX_IMAGE_SIDE);
    /* Touch every pixel (an uninitialised or short buffer shows up under ASan/MSan/valgrind). */
    unsigned sum = 0;
    for (size_t i = 0; i < img.width * img.height; i++)
        sum += img.pix[i];
    (void)sum;
    amscr_contour *c = NULL;
    amscr_status st = amscr_contour_from_mask(img.pix, img.width, img.height, img.width, AMSCR_THRESHOLD_AUTO, &c);
    FUZZ_CHECK((st == AMSCR_OK) == (c != NULL));
    amscr_contour_free(c);
    image_free(&img);
    return 0;
}

#endif
