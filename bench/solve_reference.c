/* The single solve's compiled floor: Algorithm 1's plain iteration for one member, written in
 * C for bench/bench_solve.py (compiled at bench time with gcc, called through ctypes; the
 * package never needs it).
 *
 * It is tdcm_ros.model.kernel.iterate for one member, operation for operation as numba lowers
 * it (complex products with their zero parts, numba's complex division, hypot for |z|), so it
 * gives the package's tip to the last bit. Arrays are the grid's Cells rows of member 0
 * (layout in kernel.py's docstring), C order; complex arrays interleave (real, imag).
 */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

typedef struct { double re, im; } cplx;

enum { CONVERGED = 1, NON_FINITE = 2, DIVERGING = 3, SLOWED = 4, EXHAUSTED = 5 };

static inline cplx mk(double re, double im) { cplx z = {re, im}; return z; }
static inline cplx add(cplx a, cplx b) { return mk(a.re + b.re, a.im + b.im); }
static inline cplx sub(cplx a, cplx b) { return mk(a.re - b.re, a.im - b.im); }
static inline cplx mul(cplx a, cplx b) {
    return mk(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re);
}
static inline cplx conj_(cplx a) { return mk(a.re, -a.im); }
static inline cplx div_real(cplx a, double b) {  /* numba's complex / (b + 0j), b != 0 */
    double ratio = 0.0 / b, denom = b + 0.0 * ratio;
    return mk((a.re + a.im * ratio) / denom, (a.im - a.re * ratio) / denom);
}

#define SMALL_ANGLE 0.25
#define TINY_ANGLE 0.03

static inline cplx unit(double phi) {
    double size = fabs(phi), v = phi * phi;
    if (size <= TINY_ANGLE)
        return mk(1.0 + v * (-1.0 / 2 + v * (1.0 / 24 + v * (-1.0 / 720 + v * (1.0 / 40320)))),
                  phi * (1.0 + v * (-1.0 / 6 + v * (1.0 / 120 + v * (-1.0 / 5040 + v * (
                      1.0 / 362880))))));
    if (size > SMALL_ANGLE) return mk(cos(phi), sin(phi));
    double c = 1.0 + v * (-1.0 / 2 + v * (1.0 / 24 + v * (-1.0 / 720 + v * (
        1.0 / 40320 + v * (-1.0 / 3628800 + v * (1.0 / 479001600))))));
    double s = phi * (1.0 + v * (-1.0 / 6 + v * (1.0 / 120 + v * (-1.0 / 5040 + v * (
        1.0 / 362880 + v * (-1.0 / 39916800 + v * (1.0 / 6227020800)))))));
    return mk(c, s);
}

#define FC(r, i) fc[(r) * n + (i)]
#define FQ(r, i, q) fq[((r) * n + (i)) * nq + (q)]

static void integrate_row(int n, int nq, const double *fc, const double *fq, const double *m_a,
                          const double *m_b, double tension, cplx *p, double *theta,
                          cplx *tangent) {
    cplx pos = mk(0.0, 0.0), tan = mk(1.0, 0.0);
    double th = 0.0;
    p[0] = pos; theta[0] = th; tangent[0] = tan;
    for (int i = 0; i < n; i++) {
        double a = m_a[i], b = m_b[i];
        cplx local = mk(0.0, 0.0);
        int chord = FC(2, i) != 0.0 || FC(3, i) != 0.0;
        int off_axis = FC(4, i) != 0.0 || FC(5, i) != 0.0 || FQ(5, i, 0) != 0.0;
        int compress = FQ(9, i, 0) != 0.0;
        if (!(chord || off_axis || compress)) {
            for (int q = 0; q < nq; q++)
                local = add(local, mul(mk(FQ(2, i, q), 0.0),
                                       unit(a * FQ(0, i, q) + b * FQ(1, i, q))));
            th = th + (a * FC(0, i) + b * FC(1, i));
        } else {
            for (int q = 0; q < nq; q++) {
                double phi = chord ? a * (FQ(0, i, q) + tension * FQ(3, i, q))
                                         + b * (FQ(1, i, q) + tension * FQ(4, i, q))
                                   : a * FQ(0, i, q) + b * FQ(1, i, q);
                double weight = FQ(2, i, q);
                if (off_axis) {
                    phi -= tension * FQ(7, i, q);
                    weight += a * FQ(5, i, q) + b * FQ(6, i, q) - tension * FQ(8, i, q);
                }
                if (compress) weight -= tension * FQ(9, i, q);
                local = add(local, mul(mk(weight, 0.0), unit(phi)));
            }
            double bend = chord ? a * (FC(0, i) + tension * FC(2, i))
                                      + b * (FC(1, i) + tension * FC(3, i))
                                : a * FC(0, i) + b * FC(1, i);
            if (off_axis) bend -= tension * FC(6, i);
            th = th + bend;
        }
        pos = add(pos, mul(tan, local));
        tan = mk(cos(th), sin(th));
        p[i + 1] = pos; theta[i + 1] = th; tangent[i + 1] = tan;
    }
}

static void moments_row(int n, double r_c, const cplx *p, const cplx *tangent, double t,
                        const int64_t *ic, const double *fc, double *m_a, double *m_b) {
    cplx offset = mul(mk(0.0, 1.0), mk(r_c, 0.0));
    for (int i = 0; i < n; i++) {
        double x_a = FC(4, i), x_b = FC(5, i);
        if (ic[2 * n + i] != 0) {
            m_a[i] = (r_c - x_a) * t;
            m_b[i] = (r_c - x_b) * t;
        } else {
            int64_t start = ic[i], end = ic[n + i];
            cplx anchor = add(p[start], mul(offset, tangent[start]));
            cplx chord = sub(add(p[end], mul(offset, tangent[end])), anchor);
            chord = div_real(chord, hypot(chord.re, chord.im));
            cplx at_a = p[i], at_b = p[i + 1];
            if (x_a != 0.0) at_a = add(at_a, mul(mul(mk(0.0, 1.0), mk(x_a, 0.0)), tangent[i]));
            if (x_b != 0.0)
                at_b = add(at_b, mul(mul(mk(0.0, 1.0), mk(x_b, 0.0)), tangent[i + 1]));
            m_a[i] = -t * mul(conj_(sub(anchor, at_a)), chord).im;
            m_b[i] = -t * mul(conj_(sub(anchor, at_b)), chord).im;
        }
    }
}

static double smallest_gap(int nk, double r_outer, const cplx *p, const cplx *tangent,
                           const int64_t *notch) {
    double least = INFINITY;
    for (int k = 0; k < nk; k++) {
        int64_t left = notch[k], right = notch[nk + k];
        if (left < 0 || left == right) continue;
        cplx t_l = tangent[left], t_r = tangent[right], span = sub(p[right], p[left]);
        for (int row = 2; row < 4; row++) {
            if (notch[row * nk + k] == 0) continue;
            double side = row == 2 ? 1.0 : -1.0;
            cplx arm = mul(mul(mk(0.0, 1.0), mk(side, 0.0)), mk(r_outer, 0.0));
            cplx delta = add(span, mul(arm, sub(t_r, t_l)));
            least = fmin(least, fmin(mul(conj_(t_l), delta).re, mul(conj_(t_r), delta).re));
        }
    }
    return least;
}

/* One solve: plain iteration (relaxation 1, handing over at ``slow``) from x0 (2n) into x
 * (2n), p, tangent (2 (n + 1), interleaved) and theta (n + 1); info (3 + budget) as
 * kernel.iterate's: steps, status, smallest gap (m), then the steps (m). */
int tdcm_solve(int n, int nq, int nk, const double *fc, const double *fq, const int64_t *ic,
               const int64_t *notch, const double *scal, double tension, const double *x0,
               double tol, double slow, double growth, int budget, double *x, double *p_out,
               double *theta, double *tangent_out, double *info) {
    cplx *p = (cplx *)p_out, *tangent = (cplx *)tangent_out;
    double g[2 * n], new_theta[n + 1];
    cplx new_p[n + 1], new_tangent[n + 1];
    double limit = 2.0 * scal[2], smallest = INFINITY;
    int status = EXHAUSTED, steps = 0;
    memcpy(x, x0, sizeof(double) * 2 * n);
    integrate_row(n, nq, fc, fq, x, x + n, tension, p, theta, tangent);
    for (int k = 0; k < budget; k++) {
        moments_row(n, scal[0], p, tangent, tension, ic, fc, g, g + n);
        integrate_row(n, nq, fc, fq, g, g + n, tension, new_p, new_theta, new_tangent);
        double step = 0.0;
        for (int i = 0; i <= n; i++) {
            cplx diff = sub(new_p[i], p[i]);
            double d = hypot(diff.re, diff.im);
            if (!(d <= step)) { step = d; if (isnan(d)) break; }
        }
        if (!isfinite(step)) { status = NON_FINITE; break; }
        info[3 + k] = step;
        steps = k + 1;
        memcpy(x, g, sizeof g);
        memcpy(p, new_p, sizeof new_p);
        memcpy(theta, new_theta, sizeof new_theta);
        memcpy(tangent, new_tangent, sizeof new_tangent);
        smallest = fmin(smallest, step);
        if (step <= tol) { status = CONVERGED; break; }
        if (step > limit || (k >= 5 && step > growth * smallest)) { status = DIVERGING; break; }
        if (slow > 0.0 && k >= 1 && step > slow * info[2 + k]) { status = SLOWED; break; }
    }
    info[0] = steps;
    info[1] = status;
    info[2] = smallest_gap(nk, scal[1], p, tangent, notch);
    return status;
}

/* ``repeats`` timed calls of tdcm_solve (arguments as there), each one's wall time (s) in
 * times: the compiled floor without any call overhead. */
void tdcm_time(int repeats, double *times, int n, int nq, int nk, const double *fc,
               const double *fq, const int64_t *ic, const int64_t *notch, const double *scal,
               double tension, const double *x0, double tol, double slow, double growth,
               int budget, double *x, double *p, double *theta, double *tangent, double *info) {
    struct timespec a, b;
    for (int r = 0; r < repeats; r++) {
        clock_gettime(CLOCK_MONOTONIC, &a);
        tdcm_solve(n, nq, nk, fc, fq, ic, notch, scal, tension, x0, tol, slow, growth, budget,
                   x, p, theta, tangent, info);
        clock_gettime(CLOCK_MONOTONIC, &b);
        times[r] = (double)(b.tv_sec - a.tv_sec) + 1e-9 * (double)(b.tv_nsec - a.tv_nsec);
    }
}
