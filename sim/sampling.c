/* sim/sampling.c -- seeded samples, the regression estimator and the sequential stopping rule
 * (formulas and the rule: sampling.h; design: docs/sampling.md). Pure functions: no I/O, no
 * threads, no allocation. Must not run or time anything. The numerics are GSL's: the t quantile
 * (gsl_cdf_tdist_Pinv) and the fit's Cholesky factor, triangular and Cholesky solves
 * (gsl_linalg_cholesky_decomp1, gsl_blas_dtrsv, gsl_linalg_cholesky_solve) on views of the Fit's
 * arrays; the estimator, its column choice and its jackknife are defined here. */
#include "sampling.h"

#include <gsl/gsl_blas.h>
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

uint32_t sample_count(uint32_t ntiles, double fraction)
{
    if (ntiles == 0)
        return 0;
    double want = ceil(fraction * (double)ntiles - 1e-9);
    uint32_t n = want < 2.0 ? 2u : want > (double)ntiles ? ntiles : (uint32_t)want;
    return n > ntiles ? ntiles : n;
}

uint64_t sample_splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static uint64_t sample_seed_state(uint32_t seed)
{
    return 0x5f3759dfull ^ ((uint64_t)seed << 17) ^ seed;
}

void sample_order(uint32_t N, uint32_t seed, uint32_t *order)
{
    /* Fisher-Yates from the front: order[i] is drawn uniformly from the units
     * not yet placed, so every prefix is a simple random sample without replacement (the modulo
     * bias of a 64-bit draw reduced below 2^32 is under 2^-32). */
    uint64_t s = sample_seed_state(seed);
    for (uint32_t i = 0; i < N; i++)
        order[i] = i;
    for (uint32_t i = 0; i + 1 < N; i++) {
        uint32_t j = i + (uint32_t)(sample_splitmix64(&s) % (uint64_t)(N - i));
        uint32_t t = order[i];
        order[i] = order[j];
        order[j] = t;
    }
}

/* GSL's default error handler aborts the process, and library code must never end it: it is
 * turned off before any GSL call. The factorization's status is checked (fit_factor); the
 * solves and products fail only on mismatched sizes, which the Fit's views rule out. */
static pthread_once_t gsl_once = PTHREAD_ONCE_INIT;
static void gsl_quiet(void)
{
    gsl_set_error_handler_off();
}

double sample_t975(uint32_t df)
{
    pthread_once(&gsl_once, gsl_quiet);
    if (df == 0)
        return INFINITY;
    return gsl_cdf_tdist_Pinv(0.975, (double)df);
}

/* ---- the regression (GREG) estimator ---------------------------------------------------------- */

#define FIT_CONST_TOL 1e-20 /* centred / raw sum of squares below this: a constant column */
#define FIT_PIVOT_TOL 1e-9  /* Cholesky pivot (1 - R^2 on earlier kept columns) below this: collinear */

typedef struct Fit {
    uint32_t k;                      /* columns given */
    uint32_t nkeep, keep[SAMPLE_MAX_AUX]; /* columns used, in order */
    double ybar, xbar[SAMPLE_MAX_AUX];    /* sample means */
    double s[SAMPLE_MAX_AUX][SAMPLE_MAX_AUX], sy[SAMPLE_MAX_AUX], syy; /* centred cross-products */
    double raw[SAMPLE_MAX_AUX];      /* uncentred sums of squares */
    double b[SAMPLE_MAX_AUX];        /* slopes per original column (0 for dropped ones) */
    double sse;                      /* sum of squared residuals, from the data */
    double L[SAMPLE_MAX_AUX][SAMPLE_MAX_AUX], sc[SAMPLE_MAX_AUX]; /* the kept columns' scaled Cholesky factor
                                                                    (GSL's: L lower, L' upper), their scales */
} Fit;

/* Sample means, then centred cross-products in a second pass (the two-pass form does not lose
 * the small variance of a large count to cancellation). -1 on a unit index >= N. */
static int fit_moments(Fit *f, const double *ys, const double *x, const uint32_t *sample, uint32_t n, uint32_t N)
{
    const uint32_t k = f->k;
    for (uint32_t s = 0; s < n; s++) {
        if (sample[s] >= N)
            return -1;
        f->ybar += ys[s];
        for (uint32_t j = 0; j < k; j++)
            f->xbar[j] += x[(size_t)sample[s] * k + j];
    }
    f->ybar /= n;
    for (uint32_t j = 0; j < k; j++)
        f->xbar[j] /= n;
    for (uint32_t s = 0; s < n; s++) {
        const double *xi = x ? x + (size_t)sample[s] * k : NULL;
        double dy = ys[s] - f->ybar, d[SAMPLE_MAX_AUX];
        f->syy += dy * dy;
        for (uint32_t j = 0; j < k; j++) {
            d[j] = xi[j] - f->xbar[j];
            f->raw[j] += xi[j] * xi[j];
            f->sy[j] += d[j] * dy;
            for (uint32_t l = 0; l <= j; l++)
                f->s[j][l] += d[j] * d[l];
        }
    }
    return 0;
}

/* u = C^-1 v over the kept columns (C: their centred cross-products, = D L L' D with D the
 * scales), v and u indexed by kept position: GSL's Cholesky solve of the scaled system. */
static void fit_cinv(const Fit *f, const double *v, double *u)
{
    const uint32_t m = f->nkeep;
    if (m == 0)
        return;
    double a[SAMPLE_MAX_AUX];
    for (uint32_t p = 0; p < m; p++)
        a[p] = v[p] / f->sc[p];
    gsl_matrix_const_view L = gsl_matrix_const_view_array_with_tda(&f->L[0][0], m, m, SAMPLE_MAX_AUX);
    gsl_vector_const_view av = gsl_vector_const_view_array(a, m);
    gsl_vector_view uv = gsl_vector_view_array(u, m);
    gsl_linalg_cholesky_solve(&L.matrix, &av.vector, &uv.vector);
    for (uint32_t p = 0; p < m; p++)
        u[p] /= f->sc[p];
}

/* The scaled cross-product of columns j and q (scales scj, scq): S_jq / (scj scq). */
static double fit_scaled(const Fit *f, uint32_t j, uint32_t q, double scj, double scq)
{
    return (j > q ? f->s[j][q] : f->s[q][j]) / (scj * scq);
}

/* L (its m x m top left corner): GSL's Cholesky factor of the first m kept columns' scaled
 * cross-products. They are positive definite: every kept column's pivot exceeded FIT_PIVOT_TOL. */
static int fit_factor(Fit *f, uint32_t m)
{
    for (uint32_t p = 0; p < m; p++)
        for (uint32_t q = 0; q < m; q++)
            f->L[p][q] = fit_scaled(f, f->keep[p], f->keep[q], f->sc[p], f->sc[q]);
    gsl_matrix_view L = gsl_matrix_view_array_with_tda(&f->L[0][0], m, m, SAMPLE_MAX_AUX);
    return gsl_linalg_cholesky_decomp1(&L.matrix) == GSL_SUCCESS ? 0 : -1;
}

/* Column j's squared Cholesky pivot against the kept columns, 1 - R^2 of j on them:
 * 1 - |L^-1 r|^2 with r its scaled cross-products with them (sc: j's scale). */
static double fit_pivot(const Fit *f, uint32_t j, double sc)
{
    const uint32_t m = f->nkeep;
    if (m == 0)
        return 1.0;
    double c[SAMPLE_MAX_AUX], cc;
    for (uint32_t p = 0; p < m; p++)
        c[p] = fit_scaled(f, j, f->keep[p], sc, f->sc[p]);
    gsl_matrix_const_view L = gsl_matrix_const_view_array_with_tda(&f->L[0][0], m, m, SAMPLE_MAX_AUX);
    gsl_vector_view cv = gsl_vector_view_array(c, m);
    gsl_blas_dtrsv(CblasLower, CblasNoTrans, CblasNonUnit, &L.matrix, &cv.vector);
    gsl_blas_ddot(&cv.vector, &cv.vector, &cc);
    return 1.0 - cc;
}

/* Chooses the columns (constant and collinear ones dropped, then the last kept ones until
 * n - k - 1 >= 1) and solves the normal equations of the kept ones, scaled to unit sums of
 * squares, by Cholesky: L L' beta = c, b_j = beta_j / sqrt(S_jj). */
static void fit_solve(Fit *f, uint32_t n)
{
    for (uint32_t j = 0; j < f->k; j++) {
        double sjj = f->s[j][j];
        if (!(sjj > FIT_CONST_TOL * f->raw[j]) || !(sjj > 0.0))
            continue;
        double sc = sqrt(sjj);
        if (!(fit_pivot(f, j, sc) > FIT_PIVOT_TOL))
            continue;
        f->sc[f->nkeep] = sc;
        f->keep[f->nkeep++] = j;
        /* Rounding could leave the cross-products not positive definite even past the pivot
         * test: then j is collinear after all, and the factor of the columns before it is
         * restored (it succeeded before, on the same numbers). */
        if (fit_factor(f, f->nkeep) != 0 && --f->nkeep > 0)
            (void)fit_factor(f, f->nkeep);
    }
    if (f->nkeep + 1 >= n) /* df = n - k - 1 must stay >= 1 (n >= 2 here); L's corner stays their factor */
        f->nkeep = n - 2;
    double sy[SAMPLE_MAX_AUX], beta[SAMPLE_MAX_AUX];
    for (uint32_t p = 0; p < f->nkeep; p++)
        sy[p] = f->sy[f->keep[p]];
    fit_cinv(f, sy, beta);
    for (uint32_t p = 0; p < f->nkeep; p++)
        f->b[f->keep[p]] = beta[p];
}

/* The delete-one jackknife variance of the regression estimate (sampling.h), or -1 when a unit
 * has leverage 1 (its deletion leaves the fit undetermined). Xbar: the population means of the
 * kept columns. Deleting unit s moves the estimate by -w_s e_s / (1 - h_s), where
 * w_s = N (1/n + (Xbar - xbar)' C^-1 (x_s - xbar)) is its regression weight and
 * h_s = 1/n + (x_s - xbar)' C^-1 (x_s - xbar) its leverage. */
static double fit_jackknife(const Fit *f, const double *ys, const double *x, const uint32_t *sample, uint32_t n,
                            uint32_t N, const double *Xbar)
{
    const uint32_t m = f->nkeep;
    double dX[SAMPLE_MAX_AUX] = {0}, g[SAMPLE_MAX_AUX] = {0}, sum = 0.0, sum2 = 0.0;
    for (uint32_t p = 0; p < m; p++)
        dX[p] = Xbar[p] - f->xbar[f->keep[p]];
    fit_cinv(f, dX, g);
    for (uint32_t s = 0; s < n; s++) {
        double dx[SAMPLE_MAX_AUX], q[SAMPLE_MAX_AUX], e = ys[s] - f->ybar, w = 1.0 / n, h = 1.0 / n;
        for (uint32_t p = 0; p < m; p++) {
            uint32_t j = f->keep[p];
            dx[p] = x[(size_t)sample[s] * f->k + j] - f->xbar[j];
            e -= f->b[j] * dx[p];
            w += g[p] * dx[p];
        }
        fit_cinv(f, dx, q);
        for (uint32_t p = 0; p < m; p++)
            h += dx[p] * q[p];
        if (!(1.0 - h > 1e-9))
            return -1.0;
        double d = (double)N * w * e / (1.0 - h);
        sum += d;
        sum2 += d * d;
    }
    double mean = sum / n, ss = sum2 - n * mean * mean;
    return (1.0 - (double)n / N) * (n - 1.0) / n * (ss > 0.0 ? ss : 0.0);
}

/* The residual sum of squares from the data themselves, so a perfect fit gives ~0. */
static void fit_residuals(Fit *f, const double *ys, const double *x, const uint32_t *sample, uint32_t n)
{
    for (uint32_t s = 0; s < n; s++) {
        double e = ys[s] - f->ybar;
        for (uint32_t p = 0; p < f->nkeep; p++) {
            uint32_t j = f->keep[p];
            e -= f->b[j] * (x[(size_t)sample[s] * f->k + j] - f->xbar[j]);
        }
        f->sse += e * e;
    }
}

int sample_regression_estimate(const double *ys, const double *x, uint32_t k, const uint32_t *sample,
                               uint32_t n, uint32_t N, SampleEstimate *out)
{
    pthread_once(&gsl_once, gsl_quiet);
    memset(out, 0, sizeof *out);
    out->n = n;
    out->N = N;
    if (N == 0 || n > N || k > SAMPLE_MAX_AUX || (k > 0 && !x) || (n < 2 && n < N))
        return -1;
    double sy = 0.0;
    int nonneg = 1;
    for (uint32_t s = 0; s < n; s++) {
        sy += ys[s];
        nonneg &= ys[s] >= 0.0;
    }
    if (n < 2) { /* a census of one unit */
        out->total = out->lo = out->hi = sy;
        return sample[0] < N ? 0 : -1;
    }
    Fit f;
    memset(&f, 0, sizeof f);
    f.k = k;
    if (fit_moments(&f, ys, x, sample, n, N) != 0)
        return -1;
    fit_solve(&f, n);
    fit_residuals(&f, ys, x, sample, n);
    out->k = f.nkeep;
    out->df = n - f.nkeep - 1;
    out->coef[0] = f.ybar;
    for (uint32_t j = 0; j < k; j++) {
        out->coef[1 + j] = f.b[j];
        out->coef[0] -= f.b[j] * f.xbar[j];
    }
    out->r2 = f.syy > 0.0 ? 1.0 - f.sse / f.syy : 1.0;
    out->r2 = out->r2 < 0.0 ? 0.0 : out->r2 > 1.0 ? 1.0 : out->r2;
    if (n == N) { /* a census: exact */
        out->total = out->lo = out->hi = sy;
        return 0;
    }
    double adj = 0.0, Xbar[SAMPLE_MAX_AUX]; /* b'(Xbar - xbar), Xbar over all N units */
    for (uint32_t p = 0; p < f.nkeep; p++) {
        uint32_t j = f.keep[p];
        double X = 0.0;
        for (uint32_t i = 0; i < N; i++)
            X += x[(size_t)i * k + j];
        Xbar[p] = X / N;
        adj += f.b[j] * (Xbar[p] - f.xbar[j]);
    }
    const double Nd = (double)N;
    double var = fit_jackknife(&f, ys, x, sample, n, N, Xbar);
    if (var < 0.0) /* a unit of leverage 1: the linearization variance instead */
        var = Nd * Nd * (1.0 - (double)n / Nd) / (double)n * f.sse / (double)out->df;
    out->total = Nd * (f.ybar + adj);
    out->std_error = sqrt(var);
    out->t = sample_t975(out->df);
    out->lo = out->total - out->t * out->std_error;
    out->hi = out->total + out->t * out->std_error;
    if (nonneg && out->lo < sy) /* the frame takes at least the cycles measured */
        out->lo = sy;
    return 0;
}

/* ---- the sequential rule of --target-error --------------------------------------------------- */

/* t se / |Y^|: the interval's relative half-width (0 for a census, infinite around a zero total). */
static double sample_rel_half_width(const SampleEstimate *e)
{
    double h = e->t * e->std_error;
    if (h == 0.0)
        return 0.0;
    return e->total != 0.0 ? h / fabs(e->total) : INFINITY;
}

/* The next sample size of the rule in sampling.h, for half-width h > target E > 0 at size n < N. */
static uint32_t sample_next_size(uint32_t n, uint32_t N, double h, double E)
{
    double q = E / h; /* in [0, 1): the half-width must shrink by this factor */
    double nstar = 1.0 / (1.0 / N + q * q * (1.0 / n - 1.0 / N));
    double want = ceil(1.1 * nstar);
    double step = n / 8 > 1 ? (double)(n / 8) : 1.0;
    if (!(want >= (double)n + step)) /* also catches a NaN from a NaN half-width */
        want = (double)n + step;
    if (want > 4.0 * n)
        want = 4.0 * n;
    return want > (double)N ? N : (uint32_t)want;
}

int sample_sequential(const double *x, uint32_t k, const uint32_t *order, uint32_t N, uint32_t n0, double target,
                      SampleMeasure measure, void *ctx, double *ys, SampleEstimate *out, uint32_t *rounds)
{
    memset(out, 0, sizeof *out);
    if (rounds)
        *rounds = 0;
    if (N == 0 || k > SAMPLE_MAX_AUX || (k > 0 && !x) || !order || !measure || !ys)
        return -1;
    const uint32_t least = k + 3 < N ? k + 3 : N; /* df >= 2 with every auxiliary kept */
    uint32_t n = n0 < least ? least : n0 > N ? N : n0, have = 0;
    for (;;) {
        if (measure(ctx, order + have, n - have, ys + have) != 0)
            return -1;
        have = n;
        if (rounds)
            (*rounds)++;
        if (sample_regression_estimate(ys, x, k, order, n, N, out) != 0)
            return -1;
        double h = sample_rel_half_width(out);
        if (target <= 0.0 || n == N || h <= target)
            return 0;
        n = sample_next_size(n, N, h, target);
    }
}
