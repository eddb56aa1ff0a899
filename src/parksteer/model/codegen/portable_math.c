/* Elementary functions whose every bit is fixed by this source, not by the machine's libm.
 *
 * The C library's sin, cos, exp, ... are picked at load time for the CPU (glibc has FMA and SSE2 variants, other
 * systems other libraries), and they agree only to the last bit or so. Fed into a stiff adaptive integrator, one
 * such bit becomes a 1e-5 relative difference in a figure. These functions use only +, -, *, / of IEEE doubles
 * (compiled with -ffp-contract=off, so no fused multiply-add), sqrt, floor, frexp and ldexp, which IEEE 754 fixes
 * exactly; the same operations in the same order give the same bits on any machine.
 *
 * The algorithms and coefficients are those of fdlibm (Sun Microsystems, 1993: "Permission to use, copy, modify,
 * and distribute this software is freely granted, provided that this notice is preserved."), as in FreeBSD's
 * msun: Cody-Waite argument reduction and minimax polynomials, all within 1 ulp of the true value. Branches that
 * fdlibm takes only for speed are folded into the general formula where the two give the same bits, so that the
 * numpy mirror in parksteer/portable.py, which evaluates every branch and selects, computes the same operations
 * and gets the same bits (tests/test_portable.py checks both).
 */

static const double PS_PIO2_1 = 1.57079632673412561417e+00;  /* first 33 bits of pi/2 */
static const double PS_PIO2_2 = 6.07710050630396597660e-11;  /* second 33 bits of pi/2 */
static const double PS_PIO2_2T = 2.02226624879595063154e-21; /* pi/2 - (PIO2_1 + PIO2_2) */
static const double PS_INVPIO2 = 6.36619772367581382433e-01;
/* Beyond 2^19 pi/2 the two-term reduction loses bits; the model's angles are a few turns at most. */
static const double PS_REDUCE_LIMIT = 823549.6645826427;

static void ps_reduce(double x, double *y0, double *y1, int *quadrant)
{
    /* x = n pi/2 + (y0 + y1), |y0 + y1| <= pi/4 (and a little); good to about 118 bits for |x| < 2^19 pi/2. */
    const double fn = floor(x * PS_INVPIO2 + 0.5);
    double t = x - fn * PS_PIO2_1; /* exact: fn * PIO2_1 has at most 53 bits for |fn| < 2^20 */
    double w = fn * PS_PIO2_2;
    const double r = t - w;
    w = fn * PS_PIO2_2T - ((t - r) - w);
    *y0 = r - w;
    *y1 = (r - *y0) - w;
    *quadrant = (int)(fn - 4.0 * floor(fn * 0.25));
}

static double ps_kernel_sin(double x, double y)
{
    const double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                 S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                 S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
    const double z = x * x;
    const double v = z * x;
    const double r = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    return x - ((z * (0.5 * y - v * r) - y) - v * S1);
}

static double ps_kernel_cos(double x, double y)
{
    const double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                 C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                 C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
    const double z = x * x;
    double w = z * z;
    const double r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    const double hz = 0.5 * z;
    w = 1.0 - hz;
    return w + (((1.0 - w) - hz) + (z * r - x * y));
}

static double ps_sin_quadrant(double x, int shift)
{
    /* the sine for shift 0, the cosine (the sine a quarter turn on) for shift 1: the quadrant moved on by one */
    double y0, y1;
    int n;
    if (!(fabs(x) < PS_REDUCE_LIMIT)) return x - x + NAN;
    ps_reduce(x, &y0, &y1, &n);
    switch ((n + shift) & 3) {
    case 0: return ps_kernel_sin(y0, y1);
    case 1: return ps_kernel_cos(y0, y1);
    case 2: return -ps_kernel_sin(y0, y1);
    default: return -ps_kernel_cos(y0, y1);
    }
}

static double ps_sin(double x) { return ps_sin_quadrant(x, 0); }

static double ps_cos(double x) { return ps_sin_quadrant(x, 1); }

static const double PS_ATANHI[4] = {4.63647609000806093515e-01, 7.85398163397448278999e-01,
                                    9.82793723247329054082e-01, 1.57079632679489655800e+00};
static const double PS_ATANLO[4] = {2.26987774529616870924e-17, 3.06161699786838301793e-17,
                                    1.39033110312309984516e-17, 6.12323399573676603587e-17};

static double ps_atan(double x)
{
    const double aT0 = 3.33333333333329318027e-01, aT1 = -1.99999999998764832476e-01,
                 aT2 = 1.42857142725034663711e-01, aT3 = -1.11111104054623557880e-01,
                 aT4 = 9.09088713343650656196e-02, aT5 = -7.69187620504482999495e-02,
                 aT6 = 6.66107313738753120669e-02, aT7 = -5.83357013379057348645e-02,
                 aT8 = 4.97687799461593236017e-02, aT9 = -3.65315727442169155270e-02,
                 aT10 = 1.62858201153657823623e-02;
    const double a = fabs(x);
    int id;
    double t;
    if (x != x) return x;
    if (a >= 7.378697629483821e19) return x > 0 ? PS_ATANHI[3] + PS_ATANLO[3] : -(PS_ATANHI[3] + PS_ATANLO[3]);
    if (a < 0.4375) { id = -1; t = x; }
    else if (a < 0.6875) { id = 0; t = (2.0 * a - 1.0) / (2.0 + a); }
    else if (a < 1.1875) { id = 1; t = (a - 1.0) / (a + 1.0); }
    else if (a < 2.4375) { id = 2; t = (a - 1.5) / (1.0 + 1.5 * a); }
    else { id = 3; t = -1.0 / a; }
    const double z = t * t;
    const double w = z * z;
    const double s1 = z * (aT0 + w * (aT2 + w * (aT4 + w * (aT6 + w * (aT8 + w * aT10)))));
    const double s2 = w * (aT1 + w * (aT3 + w * (aT5 + w * (aT7 + w * aT9))));
    if (id < 0) return t - t * (s1 + s2);
    const double r = PS_ATANHI[id] - ((t * (s1 + s2) - PS_ATANLO[id]) - t);
    return x < 0 ? -r : r;
}

static double ps_atan2(double y, double x)
{
    const double PI = 3.1415926535897931160e+00, PI_LO = 1.2246467991473531772e-16;
    if (x != x || y != y) return x + y;
    if (y == 0.0) return (x < 0.0 || (x == 0.0 && signbit(x))) ? (signbit(y) ? -PI : PI) : y;
    if (x == 0.0) return y > 0.0 ? PS_ATANHI[3] + PS_ATANLO[3] : -(PS_ATANHI[3] + PS_ATANLO[3]);
    const double z = ps_atan(fabs(y / x));
    if (x > 0.0) return y > 0.0 ? z : -z;
    return y > 0.0 ? PI - (z - PI_LO) : (z - PI_LO) - PI;
}

static const double PS_LN2_HI = 6.93147180369123816490e-01;
static const double PS_LN2_LO = 1.90821492927058770002e-10;
static const double PS_INVLN2 = 1.44269504088896338700e+00;

static double ps_exp(double x)
{
    const double P1 = 1.66666666666666019037e-01, P2 = -2.77777777770155933842e-03,
                 P3 = 6.61375632143793436117e-05, P4 = -1.65339022054652515390e-06,
                 P5 = 4.13813679705723846039e-08;
    if (x != x) return x;
    if (x > 7.09782712893383973096e+02) return HUGE_VAL;
    if (x < -7.45133219101941108420e+02) return 0.0;
    const double k = trunc(PS_INVLN2 * x + (x < 0.0 ? -0.5 : 0.5)); /* 0 for |x| <= ln2 / 2 */
    const double hi = x - k * PS_LN2_HI;
    const double lo = k * PS_LN2_LO;
    const double r = hi - lo;
    const double t = r * r;
    const double c = r - t * (P1 + t * (P2 + t * (P3 + t * (P4 + t * P5))));
    const double y = 1.0 - ((lo - (r * c) / (2.0 - c)) - hi);
    return ldexp(y, (int)k);
}

static double ps_expm1(double x)
{
    const double Q1 = -3.33333333333331316428e-02, Q2 = 1.58730158725481460165e-03,
                 Q3 = -7.93650757867487942473e-05, Q4 = 4.00821782732936239552e-06,
                 Q5 = -2.01099218183624371326e-07;
    if (x != x) return x;
    if (x > 7.09782712893383973096e+02) return HUGE_VAL;
    if (x < -38.0) return -1.0;
    const double k = trunc(PS_INVLN2 * x + (x < 0.0 ? -0.5 : 0.5));
    const double hi = x - k * PS_LN2_HI;
    const double lo = k * PS_LN2_LO;
    const double r = hi - lo;
    const double c = (hi - r) - lo;
    const double hfx = 0.5 * r;
    const double hxs = r * hfx;
    const double r1 = 1.0 + hxs * (Q1 + hxs * (Q2 + hxs * (Q3 + hxs * (Q4 + hxs * Q5))));
    const double t = 3.0 - r1 * hfx;
    double e = hxs * ((r1 - t) / (6.0 - r * t));
    if (k == 0.0) return r - (r * e - hxs);
    e = (r * (e - c) - c);
    e -= hxs;
    if (k == -1.0) return 0.5 * (r - e) - 0.5;
    if (k == 1.0) return r < -0.25 ? -2.0 * (e - (r + 0.5)) : 1.0 + 2.0 * (r - e);
    if (k <= -2.0 || k > 56.0) return ldexp(1.0 - (e - r), (int)k) - 1.0;
    if (k < 20.0) return ldexp((1.0 - ldexp(1.0, -(int)k)) - (e - r), (int)k);
    return ldexp((r - (e + ldexp(1.0, -(int)k))) + 1.0, (int)k);
}

static double ps_tanh(double x)
{
    const double a = fabs(x);
    double z;
    if (x != x) return x;
    if (a >= 22.0) z = 1.0;
    else if (a >= 1.0) z = 1.0 - 2.0 / (ps_expm1(2.0 * a) + 2.0);
    else {
        const double t = ps_expm1(-2.0 * a);
        z = -t / (t + 2.0);
    }
    return x < 0.0 ? -z : z;
}

static double ps_log(double x)
{
    const double Lg1 = 6.666666666666735130e-01, Lg2 = 3.999999999940941908e-01,
                 Lg3 = 2.857142874366239149e-01, Lg4 = 2.222219843214978396e-01,
                 Lg5 = 1.818357216161805012e-01, Lg6 = 1.531383769920937332e-01,
                 Lg7 = 1.479819860511658591e-01;
    if (x != x || x == HUGE_VAL) return x;
    if (x < 0.0) return (x - x) / 0.0;
    if (x == 0.0) return -HUGE_VAL;
    int e;
    double m = frexp(x, &e); /* x = m 2^e, m in [0.5, 1) */
    if (m < 0.70710678118654752440) { m *= 2.0; e -= 1; }
    const double f = m - 1.0; /* exact, in [-0.293, 0.415) */
    const double dk = (double)e;
    const double s = f / (2.0 + f);
    const double z = s * s;
    const double w = z * z;
    const double t1 = w * (Lg2 + w * (Lg4 + w * Lg6));
    const double t2 = z * (Lg1 + w * (Lg3 + w * (Lg5 + w * Lg7)));
    const double R = t2 + t1;
    const double hfsq = 0.5 * f * f;
    return dk * PS_LN2_HI - ((hfsq - (s * (hfsq + R) + dk * PS_LN2_LO)) - f);
}

static double ps_pow(double x, double y)
{
    /* Integer exponents by repeated squaring (x < 0 allowed); others as e to the y log x, x > 0, whose relative error
       is about |y log x| ulp: enough for the model's exponents (of order 1) and the integrator's step control. */
    if (y == floor(y) && fabs(y) <= 64.0) {
        unsigned n = (unsigned)fabs(y);
        double base = x, result = 1.0;
        while (n) {
            if (n & 1u) result *= base;
            n >>= 1;
            if (n) base *= base;
        }
        return y < 0.0 ? 1.0 / result : result;
    }
    if (x == 0.0) return y > 0.0 ? 0.0 : HUGE_VAL;
    return ps_exp(y * ps_log(x));
}
