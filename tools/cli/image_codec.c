/* image_codec.c — what the image decoders (image_pgm.c, image_png.c) share: the size limits
 * checked before a decoder allocates, and a decoded image freed. */
#include "image_codec.h"

#include <stdlib.h>

#include "amscr.h"
#include "util.h"

void image_free(tool_image *img)
{
    if (img) {
        free(img->pix);
        free(img->pix16);
        free(img->text);
        img->pix = NULL;
        img->pix16 = NULL;
        img->text = NULL;
        img->text_len = 0;
        img->width = img->height = 0;
    }
}

int image_check_limits(const char *path, const char *fmt, size_t w, size_t h)
{
    if (w == 0 || h == 0) {
        tool_error(path, "corrupt %s: image size is %zu x %zu", fmt, w, h);
        return -1;
    }
    if (w > AMSCR_MAX_IMAGE_SIDE || h > AMSCR_MAX_IMAGE_SIDE ||
        (double)w * (double)h > (double)AMSCR_MAX_IMAGE_PIXELS) {
        tool_error(path, "image too large: %zu x %zu pixels (limits: %d per side, %u pixels)", w, h,
                   AMSCR_MAX_IMAGE_SIDE, (unsigned)AMSCR_MAX_IMAGE_PIXELS);
        return -1;
    }
    return 0;
}
