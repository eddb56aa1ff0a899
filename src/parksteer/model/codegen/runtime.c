/* The fixed runtime of every generated model: handwheel input, Cholesky solve of the symmetric positive definite
   mass matrix, right-hand side, Jacobian, batched outputs, the prescribed-rack drive. Compiled once, apart from any
   model, with sensitivities.c and integrator.c after it (runtime.py), and linked with each model's generated
   functions; the model's dimensions (NQ, NOUT, ...) are read from the model at run time there. */

/* The loops a replay spends most of its time in (the solves below, the integrator's solves, norms and Newton
   iteration), compiled at -O2 inside a runtime compiled at -O1 (compiler.SHARED_LEVELS): they gain what the whole
   runtime at -O2 would, for a small part of its longer compile, which a first diagnosis waits for
   (docs/scaling.md). The same bits: no fused multiply-add at any level, nothing reordered. */
#define PS_HOT __attribute__((optimize("O2")))

/* ---- fixed runtime ---------------------------------------------------------------- */

int ps_nq(void) { return NQ; }
int ps_nout(void) { return NOUT; }

/* Handwheel angle and rate from the piecewise-quadratic table in p (constant outside it). */
void ps_handwheel(double t, const double *p, double *th, double *thd)
{
    const double *tab = p + INPUT_OFFSET;
    int n = (int)tab[0], k = 0;
    if (n < 1) { *th = 0.0; *thd = 0.0; return; }
    while (k + 1 < n && t >= tab[1 + 4 * (k + 1)]) k++;
    const double *piece = tab + 1 + 4 * k;
    double dt = t - piece[0];
    if (dt < 0.0) { *th = piece[1]; *thd = 0.0; return; }
    *th = piece[1] + piece[2] * dt + 0.5 * piece[3] * dt * dt;
    *thd = piece[2] + piece[3] * dt;
}

PS_HOT static void fill_lower(double *M)
{
    for (int i = 0; i < NQ; i++)
        for (int j = 0; j < i; j++) M[i * NQ + j] = M[j * NQ + i];
}

/* In-place Cholesky factor (lower) of the symmetric positive definite M; 0 on success. */
PS_HOT static int cholesky(double *M)
{
    for (int j = 0; j < NQ; j++) {
        double d = M[j * NQ + j];
        for (int k = 0; k < j; k++) d -= M[j * NQ + k] * M[j * NQ + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        M[j * NQ + j] = d;
        for (int i = j + 1; i < NQ; i++) {
            double s = M[i * NQ + j];
            for (int k = 0; k < j; k++) s -= M[i * NQ + k] * M[j * NQ + k];
            M[i * NQ + j] = s / d;
        }
    }
    return 0;
}

/* Solve L L^T x = b for `nrhs` right-hand sides stored as columns of b (row-major, stride ld). */
PS_HOT static void chol_solve(const double *L, double *b, int nrhs, int ld)
{
    for (int c = 0; c < nrhs; c++) {
        for (int i = 0; i < NQ; i++) {
            double s = b[i * ld + c];
            for (int k = 0; k < i; k++) s -= L[i * NQ + k] * b[k * ld + c];
            b[i * ld + c] = s / L[i * NQ + i];
        }
        for (int i = NQ - 1; i >= 0; i--) {
            double s = b[i * ld + c];
            for (int k = i + 1; k < NQ; k++) s -= L[k * NQ + i] * b[k * ld + c];
            b[i * ld + c] = s / L[i * NQ + i];
        }
    }
}

/* Accelerations a = M^-1 F at state y and handwheel (th, thd); leaves the factor in L. */
static int accelerations(const double *y, const double *p, double th, double thd, double *L, double *a)
{
    eval_mf(y, y + NQ, p, th, thd, L, a);
    fill_lower(L);
    if (cholesky(L)) return -1;
    chol_solve(L, a, 1, 1);
    return 0;
}

int ps_rhs(double t, const double *y, const double *p, double *ydot)
{
    double th, thd, L[NQ * NQ];
    ps_handwheel(t, p, &th, &thd);
    memcpy(ydot, y + NQ, NQ * sizeof(double));
    return accelerations(y, p, th, thd, L, ydot + NQ);
}

/* Jacobian d(ydot)/dy, row-major NY x NY. */
int ps_jac(double t, const double *y, const double *p, double *J)
{
    double th, thd, L[NQ * NQ], a[NQ], dFdq[NQ * NQ], dFdu[NQ * NQ], rhs[NQ * 2 * NQ];
    ps_handwheel(t, p, &th, &thd);
    if (accelerations(y, p, th, thd, L, a)) return -1;
    eval_jac(y, y + NQ, a, p, th, thd, dFdq, dFdu);
    for (int i = 0; i < NQ; i++)
        for (int j = 0; j < NQ; j++) {
            rhs[i * 2 * NQ + j] = dFdq[i * NQ + j];
            rhs[i * 2 * NQ + NQ + j] = dFdu[i * NQ + j];
        }
    chol_solve(L, rhs, 2 * NQ, 2 * NQ);
    memset(J, 0, NY * NY * sizeof(double));
    for (int i = 0; i < NQ; i++) {
        J[i * NY + NQ + i] = 1.0;
        for (int j = 0; j < NY; j++) J[(NQ + i) * NY + j] = rhs[i * 2 * NQ + j];
    }
    return 0;
}

/* Forcing F (full, at the handwheel input of time t) for static solves. */
void ps_forcing(double t, const double *y, const double *p, double *F)
{
    double th, thd, M[NQ * NQ];
    ps_handwheel(t, p, &th, &thd);
    eval_mf(y, y + NQ, p, th, thd, M, F);
}

/* Partial derivatives of F (a = 0) for static solves: dF/dq, row-major. */
void ps_forcing_dq(double t, const double *y, const double *p, double *dFdq)
{
    double th, thd, a[NQ], dFdu[NQ * NQ];
    memset(a, 0, sizeof a);
    ps_handwheel(t, p, &th, &thd);
    eval_jac(y, y + NQ, a, p, th, thd, dFdq, dFdu);
}

/* For a prescribed rack: mass matrix (full), forcing without the column, column direction b. */
void ps_drive(const double *y, const double *p, double *M, double *F, double *b)
{
    eval_drive(y, y + NQ, p, M, F, b);
    fill_lower(M);
}

/* Outputs at n samples: handwheel-driven (a computed here) when acc is NULL, else given a and (th, thd). */
int ps_outputs(int n, const double *t, const double *y, const double *acc, const double *hw, const double *p,
               double *out)
{
    for (int k = 0; k < n; k++) {
        const double *yk = y + k * NY;
        double th, thd, L[NQ * NQ], a[NQ];
        if (acc) {
            th = hw[2 * k]; thd = hw[2 * k + 1];
            memcpy(a, acc + k * NQ, sizeof a);
        } else {
            ps_handwheel(t[k], p, &th, &thd);
            if (accelerations(yk, p, th, thd, L, a)) return -1;
        }
        eval_outputs(yk, yk + NQ, a, p, th, thd, out + k * NOUT);
    }
    return 0;
}

/* ---- prescribed rack (parksteer.model.numeric.prescribed) ----------------------------
   The rack follows a piecewise polynomial held in one table: [pieces, order, breaks (pieces + 1),
   coefficients (order x pieces, highest power first, coefficient i of piece k at i * pieces + k)], held at its
   end values outside the breaks. The reduced state z holds the other coordinates, then their speeds. */
#define NO (NQ - 1)

/* Rack position, speed and acceleration at t (Horner with the derivatives alongside). */
PS_HOT void ps_rack(double t, const double *tab, double *r)
{
    int n = (int)tab[0], order = (int)tab[1];
    const double *x = tab + 2, *c = tab + 3 + n;
    if (t < x[0]) t = x[0];
    if (t > x[n]) t = x[n];
    int lo = 0, hi = n + 1;  /* the first break above t */
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (t < x[mid]) hi = mid; else lo = mid + 1;
    }
    int k = lo - 1;
    if (k > n - 1) k = n - 1;
    if (k < 0) k = 0;
    double h = t - x[k], position = 0.0, speed = 0.0, accel = 0.0;
    for (int i = 0; i < order; i++) {
        accel = accel * h + 2.0 * speed;
        speed = speed * h + position;
        position = position * h + c[i * n + k];
    }
    r[0] = position; r[1] = speed; r[2] = accel;
}

/* Solve A x = c in place (A n x n row-major, destroyed) by Gaussian elimination with partial pivoting. */
PS_HOT static int lu_solve(double *A, double *c, int n)
{
    for (int j = 0; j < n; j++) {
        int pivot = j;
        for (int i = j + 1; i < n; i++)
            if (fabs(A[i * n + j]) > fabs(A[pivot * n + j])) pivot = i;
        if (!(A[pivot * n + j] != 0.0)) return -1;
        if (pivot != j) {
            for (int k = 0; k < n; k++) { double s = A[j * n + k]; A[j * n + k] = A[pivot * n + k]; A[pivot * n + k] = s; }
            double s = c[j]; c[j] = c[pivot]; c[pivot] = s;
        }
        for (int i = j + 1; i < n; i++) {
            double f = A[i * n + j] / A[j * n + j];
            if (f == 0.0) continue;
            for (int k = j + 1; k < n; k++) A[i * n + k] -= f * A[j * n + k];
            c[i] -= f * c[j];
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = c[i];
        for (int k = i + 1; k < n; k++) s -= A[i * n + k] * c[k];
        c[i] = s / A[i * n + i];
    }
    return 0;
}

/* The full state y from z and the rack at t; the other accelerations and the column torque x (x[NO] the torque)
   from M a = F + b T with the rack's acceleration given; M, b as ps_drive leaves them; r the rack's motion. */
PS_HOT static int prescribed_solve(double t, const double *z, const double *p, const double *rack, double *y, double *x,
                            double *M, double *b, double *r)
{
    double F[NQ], A[NQ * NQ];
    ps_rack(t, rack, r);
    for (int i = 0, j = 0; i < NQ; i++) {
        if (i == RACK) continue;
        y[i] = z[j]; y[NQ + i] = z[NO + j]; j++;
    }
    y[RACK] = r[0]; y[NQ + RACK] = r[1];
    ps_drive(y, p, M, F, b);
    for (int i = 0; i < NQ; i++) {
        for (int j = 0, k = 0; j < NQ; j++) {
            if (j == RACK) continue;
            A[i * NQ + k++] = M[i * NQ + j];
        }
        A[i * NQ + NO] = -b[i];
        x[i] = F[i] - M[i * NQ + RACK] * r[2];
    }
    return lu_solve(A, x, NQ);
}

/* dz/dt of the reduced system. */
PS_HOT int ps_prescribed_rhs(double t, const double *z, const double *p, const double *rack, double *zdot)
{
    double y[NY], x[NQ], M[NQ * NQ], b[NQ], r[3];
    if (prescribed_solve(t, z, p, rack, y, x, M, b, r)) return -1;
    memcpy(zdot, z + NO, NO * sizeof(double));
    memcpy(zdot + NO, x, NO * sizeof(double));
    return 0;
}

/* Jacobian of the reduced system, row-major 2 NO x 2 NO: the full model's, evaluated at a constant handwheel
   input that makes its column torque the prescribed-rack torque (p_jac: the parameters with a unit column spring,
   no damper and one input piece, whose angle is set here), with the rack's row eliminated:
   d a_o / dy = J_o - (h_o / h_rack) J_rack, h = M^-1 b. */
int ps_prescribed_jac(double t, const double *z, const double *p, double *p_jac, const double *rack, double *J)
{
    double y[NY], x[NQ], M[NQ * NQ], b[NQ], r[3], acc[NQ], hw[2] = {0.0, 0.0}, out[NOUT], Jf[NY * NY];
    int reduced[2 * NO];
    if (prescribed_solve(t, z, p, rack, y, x, M, b, r)) return -1;
    for (int i = 0, j = 0; i < NQ; i++) {
        if (i == RACK) { acc[i] = r[2]; continue; }
        acc[i] = x[j]; reduced[j] = i; reduced[NO + j] = NQ + i; j++;
    }
    /* angle = column angle + torque / (unit stiffness); a column law with a dead band (rack lash) passes less
       torque for that twist: widen it by the shortfall, so that the Jacobian is exact whatever the law. */
    ps_outputs(1, &t, y, acc, hw, p_jac, out);
    hw[0] = out[OUT_COLUMN_ANGLE] + x[NO];
    ps_outputs(1, &t, y, acc, hw, p_jac, out);
    p_jac[INPUT_OFFSET + 2] = hw[0] + x[NO] - out[OUT_COLUMN_TORQUE];
    if (ps_jac(t, y, p_jac, Jf)) return -1;
    if (cholesky(M)) return -1;
    chol_solve(M, b, 1, 1);
    memset(J, 0, 4 * NO * NO * sizeof(double));
    for (int i = 0; i < NO; i++) {
        J[i * 2 * NO + NO + i] = 1.0;
        const double *row = Jf + (NQ + reduced[i]) * NY, *rack_row = Jf + (NQ + RACK) * NY;
        double ratio = b[reduced[i]] / b[RACK];
        for (int j = 0; j < 2 * NO; j++)
            J[(NO + i) * 2 * NO + j] = row[reduced[j]] - ratio * rack_row[reduced[j]];
    }
    return 0;
}

/* At m samples (t, z): the full states y (m x NY), accelerations (m x NQ) and column torques. */
int ps_prescribed_samples(int m, const double *t, const double *z, const double *p, const double *rack, double *y,
                          double *acc, double *torque)
{
    for (int k = 0; k < m; k++) {
        double x[NQ], M[NQ * NQ], b[NQ], r[3];
        if (prescribed_solve(t[k], z + k * 2 * NO, p, rack, y + k * NY, x, M, b, r)) return -1;
        for (int i = 0, j = 0; i < NQ; i++) acc[k * NQ + i] = (i == RACK) ? r[2] : x[j++];
        torque[k] = x[NO];
    }
    return 0;
}
