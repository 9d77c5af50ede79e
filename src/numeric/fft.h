/* fft.h — internal FFT (see fft.c). */
#ifndef AMSCR_FFT_H
#define AMSCR_FFT_H
#include <stddef.h>

typedef struct {
    size_t n;
    int pow2;
    double *tw;   /* 2n: e^{-2πik/n} */
    size_t *rev;  /* bit reversal (pow2) */
    double *tmp;  /* 2n scratch (direct DFT) */
} amscr__fft_plan;

int amscr__fft_plan_init(amscr__fft_plan *p, size_t n);
void amscr__fft_plan_free(amscr__fft_plan *p);
void amscr__fft(const amscr__fft_plan *p, double *z, int inverse);

#endif
