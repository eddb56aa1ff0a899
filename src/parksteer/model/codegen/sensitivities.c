/* The forward sensitivities' runtime of a generated model (parksteer.model.codegen.tangent): after runtime.c and
   before integrator.c, which calls prescribed_tangent; the model's eval_tangent is linked in (runtime.py). */

/* ---- forward sensitivities of the prescribed-rack solve ---------------------------------
   Along a direction (dz, dp) of the reduced state and the parameters, the Kane equations M a = F + b T, with the
   rack's motion given, move by A (da_o, dT) = dG, A = [M_o | -b] (the matrix prescribed_solve factors) and
   dG = G_y dy + G_p dp the directional derivative of G = F + b T - M a with a and T held (eval_tangent). So one
   call gives J dz + f_p dp, the reduced right-hand side's derivative (dz' = (du_o, da_o)), and the column torque's,
   h_z dz + h_p dp. Directions: m rows of dz (2 NO each); dps[k] the k-th direction's parameters (INPUT_OFFSET). */

int ps_sensitivities_available(void) { return PS_SENSITIVITIES; }

static int prescribed_tangent(double t, const double *z, const double *p, const double *rack, int m,
                              const double *dz, const double *const *dps, double *dzdot, double *dtorque,
                              double *dy, double *dG, double *dH)
{
    double y[NY], x[NQ], M[NQ * NQ], b[NQ], r[3], acc[NQ], A[NQ * NQ], LU[NQ * NQ], c[NQ];
    if (!PS_SENSITIVITIES || prescribed_solve(t, z, p, rack, y, x, M, b, r)) return -1;
    for (int i = 0, j = 0; i < NQ; i++) acc[i] = (i == RACK) ? r[2] : x[j++];
    for (int i = 0; i < NQ; i++) {
        for (int j = 0, k = 0; j < NQ; j++) {
            if (j == RACK) continue;
            A[i * NQ + k++] = M[i * NQ + j];
        }
        A[i * NQ + NO] = -b[i];
    }
    for (int k = 0; k < m; k++) {  /* the rack's position and speed are given: no direction moves them */
        double *d = dy + k * NY;
        for (int i = 0, j = 0; i < NQ; i++) {
            if (i == RACK) { d[i] = 0.0; d[NQ + i] = 0.0; continue; }
            d[i] = dz[k * 2 * NO + j]; d[NQ + i] = dz[k * 2 * NO + NO + j]; j++;
        }
    }
    eval_tangent(y, y + NQ, acc, p, x[NO], 0.0, 0.0, m, dy, dps, dG, dH);
    for (int k = 0; k < m; k++) {
        memcpy(LU, A, sizeof A);
        memcpy(c, dG + k * NQ, sizeof c);
        if (lu_solve(LU, c, NQ)) return -1;
        memcpy(dzdot + k * 2 * NO, dz + k * 2 * NO + NO, NO * sizeof(double));
        memcpy(dzdot + k * 2 * NO + NO, c, NO * sizeof(double));
        if (dtorque) dtorque[k] = c[NO];
    }
    return 0;
}

/* The reduced system's tangent along m directions (dz row k, parameters dp row k of INPUT_OFFSET, dp NULL: none):
   dzdot (m x 2 NO) and the column torque's dtorque (m; NULL: not wanted), MAX_TANGENTS directions at a time. */
#define MAX_TANGENTS 64
int ps_prescribed_tangent(double t, const double *z, const double *p, const double *rack, int m, const double *dz,
                          const double *dp, double *dzdot, double *dtorque)
{
    double dy[MAX_TANGENTS * NY], dG[MAX_TANGENTS * NQ], dH[MAX_TANGENTS * NQ];
    double no_parameters[INPUT_OFFSET > 0 ? INPUT_OFFSET : 1];
    const double *dps[MAX_TANGENTS];
    if (!dp) memset(no_parameters, 0, sizeof no_parameters);
    for (int start = 0; start < m; start += MAX_TANGENTS) {
        int count = m - start < MAX_TANGENTS ? m - start : MAX_TANGENTS;
        for (int k = 0; k < count; k++) dps[k] = dp ? dp + (long)(start + k) * INPUT_OFFSET : no_parameters;
        if (prescribed_tangent(t, z, p, rack, count, dz + (long)start * 2 * NO, dps, dzdot + (long)start * 2 * NO,
                               dtorque ? dtorque + start : NULL, dy, dG, dH)) return -1;
    }
    return 0;
}

/* The full forcing's derivative along m parameter directions (dp row k) at the state y (coordinates held) and
   the handwheel input of time t: the statics' f_p dp, for the initial sensitivities (implicit function theorem). */
int ps_forcing_tangent(double t, const double *y, const double *p, int m, const double *dp, double *dF)
{
    double th, thd, a[NQ], dy[MAX_TANGENTS * NY], dG[MAX_TANGENTS * NQ];
    const double *dps[MAX_TANGENTS];
    if (!PS_SENSITIVITIES) return -1;
    memset(a, 0, sizeof a);
    memset(dy, 0, sizeof dy);
    ps_handwheel(t, p, &th, &thd);
    for (int start = 0; start < m; start += MAX_TANGENTS) {
        int count = m - start < MAX_TANGENTS ? m - start : MAX_TANGENTS;
        for (int k = 0; k < count; k++) dps[k] = dp + (long)(start + k) * INPUT_OFFSET;
        eval_tangent(y, y + NQ, a, p, 0.0, th, thd, count, dy, dps, dG, dF + (long)start * NQ);
    }
    return 0;
}

/* The column torque's sensitivities at m samples (t, z, S: n_sens x 2 NO per sample) along the parameter
   directions dp (n_sens rows of INPUT_OFFSET): dtorque (m x n_sens) = h_z S + h_p v. */
int ps_prescribed_torque_sens(int m, const double *t, const double *z, const double *S, const double *p,
                              const double *rack, int n_sens, const double *dp, double *dtorque)
{
    double dzdot[MAX_TANGENTS * 2 * NO];
    if (n_sens < 1 || n_sens > MAX_TANGENTS) return -1;
    for (int k = 0; k < m; k++)
        if (ps_prescribed_tangent(t[k], z + (long)k * 2 * NO, p, rack, n_sens, S + (long)k * n_sens * 2 * NO, dp,
                                  dzdot, dtorque + (long)k * n_sens)) return -1;
    return 0;
}
