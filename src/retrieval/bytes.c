/* bytes.c — little-endian writing and bounds-checked reading (bytes.h). */
#include "bytes.h"

#include <stdlib.h>
#include <string.h>

void amscr__w_bytes(amscr__wbuf *w, const void *p, size_t n)
{
    if (w->oom || n == 0)
        return;
    if (n > SIZE_MAX / 2 - w->len) {
        w->oom = 1;
        return;
    }
    if (w->len + n > w->cap) {
        size_t cap = w->cap ? w->cap : 4096;
        while (cap < w->len + n)
            cap *= 2;
        unsigned char *nb = realloc(w->buf, cap);
        if (!nb) {
            w->oom = 1;
            return;
        }
        w->buf = nb;
        w->cap = cap;
    }
    memcpy(w->buf + w->len, p, n);
    w->len += n;
}

void amscr__w_u64(amscr__wbuf *w, uint64_t v)
{
    unsigned char b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    amscr__w_bytes(w, b, 8);
}

void amscr__w_u32(amscr__wbuf *w, uint32_t v)
{
    unsigned char b[4];
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    amscr__w_bytes(w, b, 4);
}

void amscr__w_f64(amscr__wbuf *w, double d)
{
    uint64_t v;
    memcpy(&v, &d, 8);
    amscr__w_u64(w, v);
}

void amscr__w_f64s(amscr__wbuf *w, const double *d, size_t n)
{
    for (size_t i = 0; i < n; i++)
        amscr__w_f64(w, d[i]);
}

void amscr__w_f32s(amscr__wbuf *w, const float *d, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        uint32_t v;
        memcpy(&v, &d[i], 4);
        amscr__w_u32(w, v);
    }
}

void amscr__w_str(amscr__wbuf *w, const char *s)
{
    if (!s) {
        amscr__w_u32(w, 0xffffffffu);
        return;
    }
    size_t n = strlen(s);
    if (n >= 0xffffffffu) {
        w->oom = 1;
        return;
    }
    amscr__w_u32(w, (uint32_t)n);
    amscr__w_bytes(w, s, n);
}

uint64_t amscr__r_u64(amscr__rbuf *r)
{
    if (r->bad || r->len - r->pos < 8) {
        r->bad = 1;
        return 0;
    }
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)r->p[r->pos + i] << (8 * i);
    r->pos += 8;
    return v;
}

uint32_t amscr__r_u32(amscr__rbuf *r)
{
    if (r->bad || r->len - r->pos < 4) {
        r->bad = 1;
        return 0;
    }
    uint32_t v = 0;
    for (int i = 0; i < 4; i++)
        v |= (uint32_t)r->p[r->pos + i] << (8 * i);
    r->pos += 4;
    return v;
}

double amscr__r_f64(amscr__rbuf *r)
{
    uint64_t v = amscr__r_u64(r);
    double d;
    memcpy(&d, &v, 8);
    return d;
}

static uint64_t le64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int i = 0; i < 8; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

int amscr__r_f64s(amscr__rbuf *r, double *d, size_t n)
{
    if (r->bad || (r->len - r->pos) / 8 < n) {
        r->bad = 1;
        return 0;
    }
    const unsigned char *p = r->p + r->pos;
    uint64_t inf = 0; /* any value with every exponent bit set: NaN or infinite */
    const uint64_t one = 1;
    if (*(const unsigned char *)&one == 1) { /* a little-endian host: the bytes as they are */
        memcpy(d, p, 8 * n);
        for (size_t i = 0; i < n; i++) {
            uint64_t v;
            memcpy(&v, &d[i], 8);
            inf |= (uint64_t)((v >> 52 & 0x7ff) == 0x7ff);
        }
    } else {
        for (size_t i = 0; i < n; i++) {
            uint64_t v = le64(p + 8 * i);
            inf |= (uint64_t)((v >> 52 & 0x7ff) == 0x7ff);
            memcpy(&d[i], &v, 8);
        }
    }
    r->pos += 8 * n;
    r->bad = inf != 0;
    return !r->bad;
}

int amscr__r_f32s(amscr__rbuf *r, float *d, size_t n)
{
    if (r->bad || (r->len - r->pos) / 4 < n) {
        r->bad = 1;
        return 0;
    }
    for (size_t i = 0; i < n && !r->bad; i++) {
        uint32_t v = amscr__r_u32(r);
        r->bad |= (v >> 23 & 0xff) == 0xff; /* NaN or infinite */
        memcpy(&d[i], &v, 4);
    }
    return !r->bad;
}

int amscr__r_str(amscr__rbuf *r, char **out, int *oom)
{
    uint32_t n = amscr__r_u32(r);
    *out = NULL;
    if (r->bad)
        return 0;
    if (n == 0xffffffffu)
        return 1;
    if (r->len - r->pos < n || memchr(r->p + r->pos, 0, n) != NULL) {
        r->bad = 1;
        return 0;
    }
    char *s = malloc((size_t)n + 1);
    if (!s) {
        *oom = 1;
        return 0;
    }
    memcpy(s, r->p + r->pos, n);
    s[n] = '\0';
    r->pos += n;
    *out = s;
    return 1;
}

uint64_t amscr__fnv1a(const unsigned char *p, size_t n)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

uint64_t amscr__sum64(const unsigned char *p, size_t n)
{
    const uint64_t K = 0x9E3779B97F4A7C15ull;
    uint64_t h[4] = {1469598103934665603ull, 1469598103934665603ull ^ 1u, 1469598103934665603ull ^ 2u,
                     1469598103934665603ull ^ 3u};
    size_t i = 0;
    for (; n - i >= 32; i += 32)
        for (int l = 0; l < 4; l++) { /* both steps are one-to-one: a changed word changes its lane */
            h[l] = (h[l] ^ le64(p + i + 8 * (size_t)l)) * K;
            h[l] ^= h[l] >> 29;
        }
    uint64_t r = (uint64_t)n * K;
    for (int l = 0; l < 4; l++) {
        r = (r ^ h[l]) * K;
        r ^= r >> 32;
    }
    for (; i < n; i++) {
        r ^= p[i];
        r *= 1099511628211ull;
    }
    return r ^ (r >> 31);
}
