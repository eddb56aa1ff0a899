/* Stiff integration of the model in C: one call runs a whole cycle, handwheel-driven (ps_integrate: y' = ps_rhs)
   or with the rack prescribed (ps_integrate_prescribed: the reduced system of ps_prescribed_rhs).

   The last part of the runtime's translation unit (runtime.py), after runtime.c and sensitivities.c, which define
   NY, NQ, NO, INPUT_OFFSET, ps_rhs, ps_jac, ps_prescribed_rhs, ps_prescribed_jac, PS_HOT (the mark of the loops
   compiled at -O2) and, for the sensitivities, PS_SENSITIVITIES and prescribed_tangent, and include <math.h> and
   <string.h>. Every name here
   starts with bdf_ (or is ps_integrate...), so as not to clash with the model code's own static helpers; all state
   lives on the call's stack (reentrant).

   Method: the variable-order (1 to 5), variable-step numerical differentiation formulas (NDF) of
   L. F. Shampine and M. W. Reichelt, "The MATLAB ODE Suite", SIAM J. Sci. Comput. 18 (1997) 1-22 (the
   method of MATLAB's ode15s), in the quasi-constant step-size, backward-difference form of scipy's
   solve_ivp(method="BDF") (scipy/integrate/_ivp/bdf.py, after Shampine & Reichelt and the ode15s code):
   simplified Newton iteration with the exact Jacobian, re-evaluated only when the iteration fails to
   converge; the difference array rescaled when the step changes; order and step chosen from the error
   estimates of orders q-1, q and q+1; dense output from the interpolating polynomial of the differences.

   Why this method and not a Rosenbrock one: both were built and measured on the default model's 18 s cycle
   (1,801 outputs, rtol 1e-7, the project's atol). RODAS (Hairer & Wanner's order-4(3) Rosenbrock method,
   exact Jacobian, its own order-3 continuous extension) computes very accurate step ends, but between them
   its continuous extension is accurate only to about the tolerance in the stiff components (rack speed, tyre
   twist rates), and the column damping turns rack-speed error into handwheel torque at about 37,000 N m per
   m/s: its torque was 0.006 N m from a converged run (odeint: 0.0008 N m), in 1,430 steps of 7 right-hand
   sides and a Jacobian each (about 10 ms). The NDF interpolant passes through accepted solution values,
   which lie on the slow manifold, so it is as accurate between steps as at them; a step costs about 3
   right-hand sides and 10 x 10 solves, and the Jacobian (about 4 right-hand sides' worth) is needed only
   when the Newton iteration stalls. Measured: 1,770 steps, 5,600 right-hand sides, 240 Jacobians, about
   5 ms, torque within 0.0004 N m of the converged run.

   Corners of the input (t_crit): y'' jumps there, so the differences (the solution's past) are no use across
   one. A step never crosses a corner: the last step before it is shortened to land exactly on it, and the
   integration restarts there at order 1 with a fresh Jacobian and starting step.

   Formulas (Shampine & Reichelt, section 2; the notation of scipy's bdf.py). With backward differences
   D[j] = nabla^j y_n (scaled to the current step h), order k, gamma_k = sum_{j=1..k} 1/j and
   alpha_k = (1 - kappa_k) gamma_k, the NDF of order k for y_{n+1} solves
       (1 - kappa_k) gamma_k (y_{n+1} - y_pred) + sum_{j=1..k} gamma_j nabla^j y_n = h f(t_{n+1}, y_{n+1}),
       y_pred = sum_{j=0..k} D[j],
   by the simplified Newton iteration on d = y_{n+1} - y_pred:
       (I - c J) dy = c f(t_{n+1}, y_pred + d) - psi - d,   c = h / alpha_k,
       psi = sum_{j=1..k} gamma_j D[j] / alpha_k.
   The local error is estimated as (kappa_k gamma_k + 1/(k+1)) d. kappa (Shampine & Reichelt, Table 1):
       kappa = -0.1850, -1/9, -0.0823, -0.0415, 0 for orders 1..5
   (order 5 is the plain BDF; below it the kappa term lowers the error constant, so steps are longer at the
   same accuracy, for a slightly smaller stability angle at orders 3 and 4). Step-size control as scipy:
   safety 0.9 scaled by the Newton iterations used, error^(-1/(k+1)), a step cut at most to 0.2 of itself
   after a failed error test and grown at most 10-fold.

   Forward sensitivities (ps_integrate_prescribed_sens): beside the state z, S = dz/dp . v for each of a few
   parameter directions v, by the staggered direct method (Caracotsios & Stewart, Comput. Chem. Eng. 9 (1985)
   359-365; CVODES's CV_STAGGERED): after each accepted step of the state, the same NDF of the same order on the
   same step is applied to the sensitivity equations S' = J S + f_p v. They are linear in S, so the corrector is
   one solve, d_S = (I - c J)^-1 (c (J S_pred + f_p v) - psi_S), with J exact at the step's end
   (ps_prescribed_jac, factored apart from the state's Newton matrix, which it never touches; J S_pred + f_p v from
   prescribed_tangent in one call for all directions). Each S keeps its own differences, rescaled with the state's whenever h or the order changes, and is
   interpolated as the state is. S does not enter the error control (CVODES's errconS off): the steps, and so
   every byte of the state, are those of the run without sensitivities; S is as accurate as the state's steps
   make it, which tests/model/test_sensitivities.py checks against finite differences at tight tolerances.
*/

#include <float.h>

enum { BDF_MAX_ORDER = 5, BDF_NEWTON_MAXITER = 4, BDF_MAX_SENS = 16 };
enum { BDF_OK = 0, BDF_BUDGET = 1, BDF_STEP_TOO_SMALL = 2, BDF_EVAL_FAILED = 3 };

static const double bdf_kappa[BDF_MAX_ORDER + 1] = {0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0};
static const double bdf_min_factor = 0.2;  /* the largest cut of the step after a failed error test */
static const double bdf_max_factor = 10.0; /* the largest growth of the step */
static const int bdf_max_failed_evaluations = 10; /* consecutive halvings after rhs/jac failures */

/* gamma_k, alpha_k and the error constants of the NDF of each order (index = order; [0] unused). */
typedef struct {
    double gamma[BDF_MAX_ORDER + 2];
    double alpha[BDF_MAX_ORDER + 2];
    double error_const[BDF_MAX_ORDER + 2];
} bdf_coefficients;

static void bdf_make_coefficients(bdf_coefficients *co)
{
    co->gamma[0] = 0.0;
    for (int k = 1; k <= BDF_MAX_ORDER + 1; k++) co->gamma[k] = co->gamma[k - 1] + 1.0 / k;
    for (int k = 0; k <= BDF_MAX_ORDER + 1; k++) {
        double kappa = k <= BDF_MAX_ORDER ? bdf_kappa[k] : 0.0;
        co->alpha[k] = (1.0 - kappa) * co->gamma[k];
        co->error_const[k] = kappa * co->gamma[k] + 1.0 / (k + 1);
    }
}

PS_HOT static int bdf_all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* The system integrated: the handwheel-driven model (rack NULL: y' = ps_rhs(t, y, p), n = NY), or the model with
   its rack prescribed (the reduced system z' = ps_prescribed_rhs(t, z, p, rack), n = 2 NO, its Jacobian from
   ps_prescribed_jac with the parameters p_jac, which each call writes into). Arrays are sized NY, the largest n. */
typedef struct {
    int n;
    const double *p;
    const double *rack;
    double *p_jac;
    int n_sens;             /* sensitivity directions (prescribed rack only; at most BDF_MAX_SENS) */
    const double *sens_dp;  /* their parameter directions, n_sens rows of INPUT_OFFSET */
} bdf_system;

/* The right-hand side, with non-finite results reported as failure too; counts the call. */
PS_HOT static int bdf_rhs(const bdf_system *s, double t, const double *y, double *ydot, long *n_rhs)
{
    ++*n_rhs;
    int failed = s->rack ? ps_prescribed_rhs(t, y, s->p, s->rack, ydot) : ps_rhs(t, y, s->p, ydot);
    return failed != 0 || !bdf_all_finite(ydot, s->n);
}

/* The Jacobian, row-major n x n. */
static int bdf_jac(const bdf_system *s, double t, const double *y, double *jac, long *n_jac)
{
    ++*n_jac;
    int failed = s->rack ? ps_prescribed_jac(t, y, s->p, s->p_jac, s->rack, jac) : ps_jac(t, y, s->p, jac);
    return failed != 0 || !bdf_all_finite(jac, s->n * s->n);
}

/* RMS norm of v / scale (the weighted norm of the error test and of the Newton corrections). */
PS_HOT static double bdf_norm(int n, const double *v, const double *scale)
{
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        double r = v[i] / scale[i];
        sum += r * r;
    }
    return sqrt(sum / n);
}

/* In-place LU factorisation with partial pivoting of the row-major n x n matrix A; 0, or -1 if singular. */
PS_HOT static int bdf_lu_factor(int n, double *A, int *pivot)
{
    for (int k = 0; k < n; k++) {
        int best = k;
        double largest = fabs(A[k * n + k]);
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > largest) { largest = fabs(A[i * n + k]); best = i; }
        pivot[k] = best;
        if (!(largest > 0.0) || !isfinite(largest)) return -1;
        if (best != k)
            for (int j = 0; j < n; j++) {
                double swap = A[k * n + j];
                A[k * n + j] = A[best * n + j];
                A[best * n + j] = swap;
            }
        double inverse_pivot = 1.0 / A[k * n + k];
        for (int i = k + 1; i < n; i++) {
            double factor = A[i * n + k] * inverse_pivot;
            A[i * n + k] = factor;
            if (factor != 0.0)
                for (int j = k + 1; j < n; j++) A[i * n + j] -= factor * A[k * n + j];
        }
    }
    return 0;
}

/* Solve (LU) x = b in place. The factorisation swaps whole rows (multipliers too), so all swaps are applied
   to b before the forward substitution, not interleaved with it. */
PS_HOT static void bdf_lu_solve(int n, const double *LU, const int *pivot, double *b)
{
    for (int k = 0; k < n; k++)
        if (pivot[k] != k) { double swap = b[k]; b[k] = b[pivot[k]]; b[pivot[k]] = swap; }
    for (int k = 0; k < n; k++)
        for (int i = k + 1; i < n; i++) b[i] -= LU[i * n + k] * b[k];
    for (int i = n - 1; i >= 0; i--) {
        double s = b[i];
        for (int j = i + 1; j < n; j++) s -= LU[i * n + j] * b[j];
        b[i] = s / LU[i * n + i];
    }
}

/* R[i][j] = prod_{m=1..i} (m - 1 - factor * j) / m (R[0][j] = 1, R[i][0] = 0 for i >= 1): the matrix that
   re-expresses backward differences on a grid of spacing h as differences on spacing factor * h
   (Shampine & Reichelt, section 3; scipy's compute_R). */
static void bdf_compute_R(int order, double factor, double R[BDF_MAX_ORDER + 1][BDF_MAX_ORDER + 1])
{
    for (int j = 0; j <= order; j++) R[0][j] = 1.0;
    for (int i = 1; i <= order; i++) {
        R[i][0] = 0.0;
        for (int j = 1; j <= order; j++) R[i][j] = R[i - 1][j] * (i - 1 - factor * j) / i;
    }
}

/* Rescale the differences D[0..order] (rows `stride` apart, `width` values each) from step h to step factor * h
   (the same interpolating polynomial). */
PS_HOT static void bdf_rescale(int width, double *D, int stride, int order, double factor)
{
    double R[BDF_MAX_ORDER + 1][BDF_MAX_ORDER + 1], U[BDF_MAX_ORDER + 1][BDF_MAX_ORDER + 1];
    double RU[BDF_MAX_ORDER + 1][BDF_MAX_ORDER + 1], old[BDF_MAX_ORDER + 1];
    bdf_compute_R(order, factor, R);
    bdf_compute_R(order, 1.0, U);
    for (int i = 0; i <= order; i++)
        for (int j = 0; j <= order; j++) {
            double s = 0.0;
            for (int m = 0; m <= order; m++) s += R[i][m] * U[m][j];
            RU[i][j] = s;
        }
    for (int i = 0; i < width; i++) {
        for (int m = 0; m <= order; m++) old[m] = D[m * stride + i];
        for (int j = 0; j <= order; j++) {
            double s = 0.0;
            for (int m = 0; m <= order; m++) s += RU[m][j] * old[m];
            D[j * stride + i] = s;
        }
    }
}

/* Differences of the sensitivities: BDF_MAX_ORDER + 3 rows of n_sens x n (direction k's at k * n). A row's length,
   not a typedef: NY may be the run-time dimension of a runtime compiled once for every model (runtime.py). */
#define BDF_SENS_ROW (BDF_MAX_SENS * NY)

/* Rescale the state's differences and the sensitivities' alike. */
static void bdf_change_D(const bdf_system *s, double D[][NY], double DS[][BDF_SENS_ROW], int order, double factor)
{
    bdf_rescale(s->n, &D[0][0], NY, order, factor);
    if (s->n_sens) bdf_rescale(s->n * s->n_sens, &DS[0][0], BDF_MAX_SENS * NY, order, factor);
}

/* The first end point after t that a step may not cross: the nearest t_crit beyond t, or t_end. */
static double bdf_next_stop(double t, double t_end, int n_crit, const double *t_crit)
{
    double stop = t_end;
    for (int i = 0; i < n_crit; i++)
        if (t_crit[i] > t && t_crit[i] < stop) stop = t_crit[i];
    return stop;
}

/* Starting step for order 1 (Hairer, Norsett & Wanner, "Solving ODEs I", section II.4; as scipy's
   select_initial_step): an explicit Euler trial step estimates y'' and the step is chosen so that its
   local error is about 1 % of the tolerance, capped by the distance to the next stop. One right-hand side;
   if it fails, a cautious guess (the error test takes over). */
static double bdf_initial_step(const bdf_system *s, double t, const double *y, const double *f, double rtol,
                               const double *atol, double stop, long *n_rhs)
{
    const int n = s->n;
    double scale[NY], y_euler[NY], f_euler[NY], difference[NY];
    for (int i = 0; i < n; i++) scale[i] = atol[i] + rtol * fabs(y[i]);
    double d0 = bdf_norm(n, y, scale), d1 = bdf_norm(n, f, scale);
    double span = stop - t;
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h0 = fmin(h0, span);
    for (int i = 0; i < n; i++) y_euler[i] = y[i] + h0 * f[i];
    if (bdf_rhs(s, t + h0, y_euler, f_euler, n_rhs)) return fmin(h0, 1e-6 * span);
    for (int i = 0; i < n; i++) difference[i] = f_euler[i] - f[i];
    double d2 = bdf_norm(n, difference, scale) / h0;
    double h1 = (d1 <= 1e-15 && d2 <= 1e-15) ? fmax(1e-6, 1e-3 * h0) : sqrt(0.01 / fmax(d1, d2));
    return fmin(fmin(100.0 * h0, h1), span);
}

/* Simplified Newton iteration for the NDF step (scipy's solve_bdf_system): on success, y_new and
   d = y_new - y_pred. Stops early when the observed contraction rate says tol cannot be reached within the
   iteration limit. *evaluation_failed tells a failed right-hand side from slow convergence. */
PS_HOT static int bdf_newton(const bdf_system *s, double t_new, const double *y_pred, double c, const double *psi, const double *lu,
                      const int *pivot, const double *scale, double tol, double *y_new, double *d,
                      int *n_iter, int *evaluation_failed, long *n_rhs)
{
    const int n = s->n;
    double f[NY], dy[NY], dy_norm_old = 0.0;
    memcpy(y_new, y_pred, n * sizeof(double));
    memset(d, 0, n * sizeof(double));
    *evaluation_failed = 0;
    for (int k = 0; k < BDF_NEWTON_MAXITER; k++) {
        *n_iter = k + 1;
        if (bdf_rhs(s, t_new, y_new, f, n_rhs)) { *evaluation_failed = 1; return 0; }
        for (int i = 0; i < n; i++) dy[i] = c * f[i] - psi[i] - d[i];
        bdf_lu_solve(n, lu, pivot, dy);
        double dy_norm = bdf_norm(n, dy, scale);
        double rate = k > 0 ? dy_norm / dy_norm_old : -1.0;
        if (k > 0 && (rate >= 1.0 || ps_pow(rate, BDF_NEWTON_MAXITER - k) / (1.0 - rate) * dy_norm > tol)) return 0;
        for (int i = 0; i < n; i++) { y_new[i] += dy[i]; d[i] += dy[i]; }
        if (dy_norm == 0.0 || (k > 0 && rate / (1.0 - rate) * dy_norm < tol)) return 1;
        dy_norm_old = dy_norm;
    }
    return 0;
}

/* The interpolating polynomial of the differences (rows `stride` apart, `width` values each) at time t (scipy's
   BdfDenseOutput): y at t_now, and prod_{m<j} (t - t_now + m h) / ((m + 1) h) times D[j]. */
PS_HOT static void bdf_interpolate(int width, double t, double t_now, double h, int order, const double *D, int stride,
                            double *y)
{
    double product = 1.0;
    memcpy(y, D, width * sizeof(double));
    for (int j = 1; j <= order; j++) {
        product *= (t - (t_now - (j - 1) * h)) / (j * h);
        for (int i = 0; i < width; i++) y[i] += D[j * stride + i] * product;
    }
}

/* The sensitivities' right-hand sides J S + f_p v at (t, z) for S = rows of `S` (n_sens x n), into f. */
static int bdf_sens_rhs(const bdf_system *s, double t, const double *z, const double *S, double *f)
{
    const int n = s->n, m = s->n_sens;
    double dy[BDF_MAX_SENS * NY], dG[BDF_MAX_SENS * NQ], dH[BDF_MAX_SENS * NQ];
    const double *dps[BDF_MAX_SENS];
    for (int k = 0; k < m; k++) dps[k] = s->sens_dp + (long)k * INPUT_OFFSET;
    if (prescribed_tangent(t, z, s->p, s->rack, m, S, dps, f, NULL, dy, dG, dH)) return 1;
    return !bdf_all_finite(f, m * n);
}

/* The sensitivities' NDF step of the given order and h to t_new, whose state y_new the step has just accepted:
   the linear corrector solved with the LU of I - c J at (t_new, y_new), then the differences updated as the
   state's. 0, or 1 when the sensitivities' right-hand side fails or I - c J is singular. */
static int bdf_sens_step(const bdf_system *s, const bdf_coefficients *co, double t_new, const double *y_new,
                         double h, int order, double DS[][BDF_SENS_ROW])
{
    const int n = s->n, w = s->n * s->n_sens;
    double S_pred[BDF_MAX_SENS * NY], psi[BDF_MAX_SENS * NY], f[BDF_MAX_SENS * NY], d[BDF_MAX_SENS * NY];
    double jac[NY * NY], lu[NY * NY];
    int pivot[NY];
    const double c = h / co->alpha[order];
    for (int i = 0; i < w; i++) {
        double sum = 0.0, weighted = 0.0;
        for (int j = 0; j <= order; j++) sum += DS[j][i];
        for (int j = 1; j <= order; j++) weighted += co->gamma[j] * DS[j][i];
        S_pred[i] = sum;
        psi[i] = weighted / co->alpha[order];
    }
    long n_jac = 0;
    if (bdf_jac(s, t_new, y_new, jac, &n_jac) || bdf_sens_rhs(s, t_new, y_new, S_pred, f)) return 1;
    for (int i = 0; i < n * n; i++) lu[i] = -c * jac[i];
    for (int i = 0; i < n; i++) lu[i * n + i] += 1.0;
    if (bdf_lu_factor(n, lu, pivot)) return 1;
    for (int k = 0; k < s->n_sens; k++) {
        for (int i = 0; i < n; i++) d[k * n + i] = c * f[k * n + i] - psi[k * n + i];
        bdf_lu_solve(n, lu, pivot, d + k * n);
    }
    for (int i = 0; i < w; i++) {
        DS[order + 2][i] = d[i] - DS[order + 1][i];
        DS[order + 1][i] = d[i];
    }
    for (int j = order; j >= 0; j--)
        for (int i = 0; i < w; i++) DS[j][i] += DS[j + 1][i];
    return 0;
}

/* Integrate the system s from t_out[0] (state y0) and write the state at every t_out[k] (increasing)
   into y_out[k*n ...] (y_out[0..n) = y0). No step crosses a t_crit value: each is reached exactly and the
   method restarts there. Error weights rtol |y_i| + atol[i], RMS norm. max_steps bounds the step attempts
   (rejected ones included) between two consecutive output times, as odeint's mxstep. stats[0..4): accepted
   steps, rhs calls, jac calls, last time reached. Returns 0 on success, 1 step budget exceeded, 2 step size
   too small (h < 1e-14 |t|), 3 rhs or jac failed (nonzero or non-finite) at the start of a piece, or still
   after 10 halvings of the step. */
static int bdf_solve(const bdf_system *s, const double *y0, int n_out, const double *t_out, int n_crit,
                     const double *t_crit, double rtol, const double *atol, long max_steps, double *y_out,
                     double *stats, const double *s0, double *s_out)
{
    const int n = s->n, w = s->n * s->n_sens;
    long n_steps = 0, n_rhs = 0, n_jac = 0;
    double t = n_out > 0 ? t_out[0] : 0.0;
    int status = BDF_OK;
    if (n_out > 0) memcpy(y_out, y0, n * sizeof(double));

    bdf_coefficients co;
    bdf_make_coefficients(&co);
    rtol = fmax(rtol, 100.0 * DBL_EPSILON); /* tighter than rounding allows is no tolerance (as scipy) */
    const double newton_tol = fmax(10.0 * DBL_EPSILON / rtol, fmin(0.03, sqrt(rtol)));
    const double t_end = n_out > 0 ? t_out[n_out - 1] : t;

    double D[BDF_MAX_ORDER + 3][NY]; /* D[0] = y at t; D[j] = j-th backward difference on spacing h */
    double jac[NY * NY], lu[NY * NY], f[NY];
    double y_pred[NY], y_new[NY], d[NY], psi[NY], scale[NY], error[NY];
    int pivot[NY];
    double DS[BDF_MAX_ORDER + 3][BDF_SENS_ROW]; /* the sensitivities' differences, as D (s->n_sens of them) */
    double h = 0.0, c_factored = 0.0; /* c of the current LU; 0 = no valid LU */
    int order = 1, n_equal_steps = 0, jac_is_current = 0, restart = 1, failed_evaluations = 0;
    int next_out = 1;
    long attempts_since_output = 0;
    memcpy(D[0], y0, n * sizeof(double));
    if (w) {
        memset(DS, 0, sizeof DS);
        memcpy(DS[0], s0, w * sizeof(double));
        if (n_out > 0) memcpy(s_out, s0, w * sizeof(double));
    }

    while (next_out < n_out) {
        double stop = bdf_next_stop(t, t_end, n_crit, t_crit);

        /* A stop a few rounding errors away (a corner and t_end that differ in the last digits): no step can
           resolve it, and y changes by no more than rounding there, so arrive by moving t alone. */
        if (stop - t <= 64.0 * DBL_EPSILON * fabs(stop)) {
            t = stop;
            for (; next_out < n_out && t_out[next_out] <= t; ++next_out) {
                memcpy(y_out + (long)next_out * n, D[0], n * sizeof(double));
                if (w) memcpy(s_out + (long)next_out * w, DS[0], w * sizeof(double));
            }
            attempts_since_output = 0;
            restart = 1;
            continue;
        }

        if (restart) { /* at the start and at each corner: order 1, fresh Jacobian, new starting step */
            if (bdf_rhs(s, t, D[0], f, &n_rhs) || bdf_jac(s, t, D[0], jac, &n_jac)) {
                status = BDF_EVAL_FAILED;
                goto done;
            }
            h = bdf_initial_step(s, t, D[0], f, rtol, atol, stop, &n_rhs);
            for (int i = 0; i < n; i++) D[1][i] = h * f[i];
            if (w) {
                double f_sens[BDF_MAX_SENS * NY];
                if (bdf_sens_rhs(s, t, D[0], DS[0], f_sens)) { status = BDF_EVAL_FAILED; goto done; }
                for (int i = 0; i < w; i++) DS[1][i] = h * f_sens[i];
            }
            order = 1;
            n_equal_steps = 0;
            jac_is_current = 1;
            c_factored = 0.0;
            restart = 0;
        }

        /* One step: retried with a smaller h until the Newton iteration converges and the error test passes. */
        int n_iter = 0;
        double t_new;
        for (;;) {
            if (attempts_since_output >= max_steps) { status = BDF_BUDGET; goto done; }
            if (!(h >= 1e-14 * fabs(t)) || !(h > 0.0)) { status = BDF_STEP_TOO_SMALL; goto done; }
            ++attempts_since_output;

            if (t + 1.0001 * h >= stop) { /* land exactly on the stop (stretching h by up to 0.01 %) */
                double shortened = stop - t;
                bdf_change_D(s, D, DS, order, shortened / h);
                h = shortened;
                n_equal_steps = 0;
                t_new = stop;
            } else {
                t_new = t + h;
            }

            for (int i = 0; i < n; i++) {
                double sum = 0.0, weighted = 0.0;
                for (int j = 0; j <= order; j++) sum += D[j][i];
                for (int j = 1; j <= order; j++) weighted += co.gamma[j] * D[j][i];
                y_pred[i] = sum;
                psi[i] = weighted / co.alpha[order];
                scale[i] = atol[i] + rtol * fabs(sum);
            }
            const double c = h / co.alpha[order];

            int converged = 0, evaluation_failed = 0;
            for (;;) {
                if (c != c_factored) { /* the LU is cheap at this size: refactor whenever h or order changes */
                    for (int i = 0; i < n * n; i++) lu[i] = -c * jac[i];
                    for (int i = 0; i < n; i++) lu[i * n + i] += 1.0;
                    c_factored = bdf_lu_factor(n, lu, pivot) ? 0.0 : c;
                }
                if (c_factored != 0.0)
                    converged = bdf_newton(s, t_new, y_pred, c, psi, lu, pivot, scale, newton_tol, y_new, d,
                                           &n_iter, &evaluation_failed, &n_rhs);
                if (converged || jac_is_current) break;
                /* Slow convergence with an old Jacobian: refresh it at the predicted point and retry. */
                if (bdf_jac(s, t_new, y_pred, jac, &n_jac)) { evaluation_failed = 1; break; }
                jac_is_current = 1;
                c_factored = 0.0;
            }
            if (!converged) {
                if (evaluation_failed && ++failed_evaluations > bdf_max_failed_evaluations) {
                    status = BDF_EVAL_FAILED;
                    goto done;
                }
                bdf_change_D(s, D, DS, order, 0.5);
                h *= 0.5;
                n_equal_steps = 0;
                continue;
            }

            double safety = 0.9 * (2 * BDF_NEWTON_MAXITER + 1) / (2 * BDF_NEWTON_MAXITER + n_iter);
            for (int i = 0; i < n; i++) {
                scale[i] = atol[i] + rtol * fabs(y_new[i]);
                error[i] = co.error_const[order] * d[i];
            }
            double error_norm = bdf_norm(n, error, scale);
            if (error_norm > 1.0) {
                double factor = fmax(bdf_min_factor, safety * ps_pow(error_norm, -1.0 / (order + 1)));
                bdf_change_D(s, D, DS, order, factor);
                h *= factor;
                n_equal_steps = 0;
                continue;
            }

            /* Accepted: update the differences. d = nabla^{k+1} y_{n+1} for the new point, and
               nabla^{j+1} y_{n+1} = nabla^j y_{n+1} - nabla^j y_n gives the rest from the top down. */
            ++n_steps;
            ++n_equal_steps;
            failed_evaluations = 0;
            jac_is_current = 0;
            for (int i = 0; i < n; i++) {
                D[order + 2][i] = d[i] - D[order + 1][i];
                D[order + 1][i] = d[i];
            }
            for (int j = order; j >= 0; j--)
                for (int i = 0; i < n; i++) D[j][i] += D[j + 1][i];
            t = t_new;
            if (w && bdf_sens_step(s, &co, t, D[0], h, order, DS)) { status = BDF_EVAL_FAILED; goto done; }

            /* After order + 1 steps of equal size: choose order q-1, q or q+1 and the next step from the error
               estimates of each (the order allowing the longest step wins). */
            if (n_equal_steps >= order + 1) {
                double factor_lower = 0.0, factor_same, factor_higher = 0.0;
                if (order > 1) {
                    for (int i = 0; i < n; i++) error[i] = co.error_const[order - 1] * D[order][i];
                    factor_lower = ps_pow(bdf_norm(n, error, scale), -1.0 / order);
                }
                factor_same = ps_pow(error_norm, -1.0 / (order + 1));
                if (order < BDF_MAX_ORDER) {
                    for (int i = 0; i < n; i++) error[i] = co.error_const[order + 1] * D[order + 2][i];
                    factor_higher = ps_pow(bdf_norm(n, error, scale), -1.0 / (order + 2));
                }
                double best = factor_same;
                int new_order = order;
                if (factor_lower > best) { best = factor_lower; new_order = order - 1; }
                if (factor_higher > best) { best = factor_higher; new_order = order + 1; }
                order = new_order;
                double factor = fmin(bdf_max_factor, safety * best);
                bdf_change_D(s, D, DS, order, factor);
                h *= factor;
                n_equal_steps = 0;
            }
            break;
        }

        /* Outputs within the step just taken: the interpolating polynomial (exact at the step's end). */
        if (t_out[next_out] <= t) {
            while (next_out < n_out && t_out[next_out] <= t) {
                double *row = y_out + (long)next_out * n;
                if (t_out[next_out] == t) memcpy(row, D[0], n * sizeof(double));
                else bdf_interpolate(n, t_out[next_out], t, h, order, &D[0][0], NY, row);
                if (w) {
                    double *sens_row = s_out + (long)next_out * w;
                    if (t_out[next_out] == t) memcpy(sens_row, DS[0], w * sizeof(double));
                    else bdf_interpolate(w, t_out[next_out], t, h, order, &DS[0][0], BDF_MAX_SENS * NY, sens_row);
                }
                ++next_out;
            }
            attempts_since_output = 0;
        }
        if (t == stop && stop < t_end) restart = 1; /* a corner: the past is no guide beyond it */
    }

done:
    if (stats) {
        stats[0] = (double)n_steps;
        stats[1] = (double)n_rhs;
        stats[2] = (double)n_jac;
        stats[3] = t;
    }
    return status;
}

/* The handwheel-driven model: y' = ps_rhs(t, y, p), NY states (bdf_solve). */
int ps_integrate(const double *p, const double *y0, int n_out, const double *t_out, int n_crit, const double *t_crit,
                 double rtol, const double *atol, long max_steps, double *y_out, double *stats)
{
    const bdf_system s = {NY, p, NULL, NULL, 0, NULL};
    return bdf_solve(&s, y0, n_out, t_out, n_crit, t_crit, rtol, atol, max_steps, y_out, stats, NULL, NULL);
}

/* The model with its rack prescribed by the table `rack` (ps_rack): the reduced system of the other coordinates,
   z' = ps_prescribed_rhs(t, z, p, rack), 2 NO states; p_jac as ps_prescribed_jac takes it (bdf_solve). */
int ps_integrate_prescribed(const double *p, double *p_jac, const double *rack, const double *z0, int n_out,
                            const double *t_out, int n_crit, const double *t_crit, double rtol, const double *atol,
                            long max_steps, double *z_out, double *stats)
{
    const bdf_system s = {2 * NO, p, rack, p_jac, 0, NULL};
    return bdf_solve(&s, z0, n_out, t_out, n_crit, t_crit, rtol, atol, max_steps, z_out, stats, NULL, NULL);
}

/* ps_integrate_prescribed with forward sensitivities along n_sens (1 to BDF_MAX_SENS; else -1) parameter
   directions dp (n_sens rows of INPUT_OFFSET): from s0 (n_sens x 2 NO, direction k's at k * 2 NO), s_out
   (n_out x n_sens x 2 NO) gets dz/dp . v at every output time. The state's steps and values are those of
   ps_integrate_prescribed. */
int ps_integrate_prescribed_sens(const double *p, double *p_jac, const double *rack, const double *z0, int n_out,
                                 const double *t_out, int n_crit, const double *t_crit, double rtol,
                                 const double *atol, long max_steps, double *z_out, double *stats, int n_sens,
                                 const double *dp, const double *s0, double *s_out)
{
    if (!PS_SENSITIVITIES || n_sens < 1 || n_sens > BDF_MAX_SENS) return -1;
    const bdf_system s = {2 * NO, p, rack, p_jac, n_sens, dp};
    return bdf_solve(&s, z0, n_out, t_out, n_crit, t_crit, rtol, atol, max_steps, z_out, stats, s0, s_out);
}
