/* The assisted replay's torsion-bar inversion (parksteer.model.numeric.torsion_bar, BoostLaw.torsion_bar): at each
 * sample, the torsion-bar torque T with T + f A(T) = y, A the boost law of
 * parksteer.model.symbolic.effects.assist_common (its ramp, dead band, clamp, gear direction and table law, each
 * with the same operations in the same order), by regula falsi with the Illinois rule in a bracket kept about the
 * root.
 *
 * Each sample's steps are its own, so this gives, sample by sample, what stepping the open samples together in
 * numpy gave. Only +, -, *, / of doubles, sqrt, fabs and comparisons, written in the order the law's Python writes
 * them (left to right), compiled without fused multiply-add (-ffp-contract=off) and without -ffast-math: the same
 * bits on any machine. A comparison with a NaN is false, as numpy's is: a NaN secant point falls to the bracket's
 * midpoint, a NaN value of the balance counts as below the root.
 */
#include <float.h>
#include <math.h>

#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "the inversion's arithmetic must be carried in doubles (FLT_EVAL_METHOD 0: SSE2 on x86, any 64-bit target)"
#endif

/* The law's values, in this order (torsion_bar.LAW_FIELDS; checked when the library is loaded). */
enum { GAIN, DEAD_BAND, BAND_WIDTH, LINE_SCALE, TABLE_SCALE, LIMIT, LIMIT_WIDTH, AREA, RATIO, EFFICIENCY, REDUCTION,
       BACK_EFFICIENCY, DIRECTION_WIDTH, ASSIST_SCALE };
const char ps_torsion_bar_fields[] = "gain,dead_band,band_width,line_scale,table_scale,limit,limit_width,area,ratio,"
                                     "efficiency,reduction,back_efficiency,direction_width,assist_scale";

typedef struct {
    const double *v;      /* the values above */
    int hydraulic;        /* a valve (pressure times piston area) rather than a motor through a reduction */
    int points;           /* the boost table's points; 0: no table */
    const double *knots;  /* its torques (rising), assists and slopes at the law's speed, `points` each */
    const double *assist;
    const double *slope;
} Law;

/* assist_common.ramp: a smooth max(z, 0) */
static double ramp(double z, double width)
{
    return (z + sqrt(z * z + width * width)) / 2.0;
}

/* assist_common.deadband */
static double deadband(double x, double band, double width)
{
    return ramp(x - band, width) - ramp(-x - band, width);
}

/* assist_common.clamp */
static double clamp(double y, double limit, double width)
{
    return y - ramp(y - limit, width) + ramp(-y - limit, width);
}

/* assist_common.directional_efficiency, the tanh of sharpness times speed given (`direction`, read by numpy) */
static double directional_efficiency(double motor, double direction, double forward, double back, double width)
{
    double s = direction * motor / sqrt(motor * motor + width * width);
    return 1.0 + s * ((forward - 1.0) * (1.0 + s) / 2.0 + (1.0 - 1.0 / back) * (1.0 - s) / 2.0);
}

/* assist_common.table_law on a table read at one speed (_half_numeric and _hermite): the first segment k with
 * |torque| < knots[k + 1], found as numpy's searchsorted(knots[1:], |torque|, side="right") finds it in rising
 * knots (a NaN beyond every knot), the line of the last point's slope beyond the last knot; odd in the torque. */
static double table_law(double torque, const Law *law)
{
    const double *knots = law->knots, *assist = law->assist, *slope = law->slope;
    int last = law->points - 1, low = 0, length = last;
    double x = fabs(torque), magnitude;
    while (length > 0) { /* the number of knots[1..last] at or below x */
        int half = length / 2;
        if (!(x < knots[low + half + 1])) {
            low += half + 1;
            length -= half + 1;
        } else {
            length = half;
        }
    }
    if (low == last) {
        magnitude = assist[last] + slope[last] * (x - knots[last]);
    } else {
        int k = low;
        double h = knots[k + 1] - knots[k];
        double s = (x - knots[k]) / h;
        double r = 1.0 - s;
        magnitude = assist[k] * ((1.0 + 2.0 * s) * r * r) + h * slope[k] * (s * r * r)
                    + assist[k + 1] * (s * s * (3.0 - 2.0 * s)) + h * slope[k + 1] * (s * s * (s - 1.0));
    }
    return torque >= 0.0 ? magnitude : -magnitude;
}

/* Samples stepped side by side: enough for the processor to overlap their square roots and divisions. */
#define LANES 64

/* x + f A(x) - y at `count` samples side by side (each one's x, y, factor f and gear direction d; `factor` NULL:
 * a motor delivering what the law commands, no product; `direction` NULL: a valve), into `out`: the law's demand
 * (the line through the dead band, the table's), clamped to the motor's limit (the valve's relief pressure),
 * delivered through the gear in the direction the power flows (a motor's) and referred to the torsion bar. Each
 * stage is a loop over the samples, whose operations are independent. */
static void excess(const Law *law, int count, const double *x, const double *y, const double *factor,
                   const double *direction, double *out)
{
    const double *v = law->v;
    const double gain = v[GAIN], band = v[DEAD_BAND], band_width = v[BAND_WIDTH], line_scale = v[LINE_SCALE],
                 table_scale = v[TABLE_SCALE], limit = v[LIMIT], limit_width = v[LIMIT_WIDTH], area = v[AREA],
                 ratio = v[RATIO], efficiency = v[EFFICIENCY], reduction = v[REDUCTION], back = v[BACK_EFFICIENCY],
                 direction_width = v[DIRECTION_WIDTH], assist_scale = v[ASSIST_SCALE];
    double demand[LANES];
    for (int j = 0; j < count; j++)
        demand[j] = gain * deadband(x[j], band, band_width);
    if (line_scale != 1.0) /* a rack motor's line, in the rack's units */
        for (int j = 0; j < count; j++)
            demand[j] = demand[j] * line_scale;
    if (law->points)
        for (int j = 0; j < count; j++) {
            double table = table_law(x[j], law);
            demand[j] = demand[j] + (table_scale == 1.0 ? table : table_scale * table);
        }
    if (law->hydraulic) {
        for (int j = 0; j < count; j++)
            out[j] = area * clamp(demand[j], limit, limit_width) / ratio;
    } else {
        for (int j = 0; j < count; j++) {
            double motor = clamp(demand[j] / (efficiency * reduction), limit, limit_width);
            demand[j] = motor;
        }
        for (int j = 0; j < count; j++) {
            double motor = demand[j];
            double delivered = directional_efficiency(motor, direction[j], efficiency, back, direction_width);
            out[j] = delivered * reduction * motor;
        }
        if (assist_scale != 1.0) /* a rack motor's assist, at the torsion bar */
            for (int j = 0; j < count; j++)
                out[j] = out[j] / assist_scale;
    }
    for (int j = 0; j < count; j++)
        out[j] = x[j] + (factor ? factor[j] * out[j] : out[j]) - y[j];
}

/* The samples of one block that are still open, packed: each one's index, y, factor, direction, bracket, the
 * balance's values at its ends and the end the last step moved (-1 low, +1 high, 0 none yet). */
typedef struct {
    long index[LANES];
    double y[LANES], factor[LANES], direction[LANES], low[LANES], high[LANES], f_low[LANES], f_high[LANES];
    int side[LANES];
} Open;

/* The open sample at j closed: its torque, the bracket's midpoint, written; the last open one moved into its place
 * (`count` one less). */
static void close_sample(Open *s, int j, int *count, double *out)
{
    int last = --*count;
    out[s->index[j]] = 0.5 * (s->low[j] + s->high[j]);
    s->index[j] = s->index[last];
    s->y[j] = s->y[last];
    s->factor[j] = s->factor[last];
    s->direction[j] = s->direction[last];
    s->low[j] = s->low[last];
    s->high[j] = s->high[last];
    s->f_low[j] = s->f_low[last];
    s->f_high[j] = s->f_high[last];
    s->side[j] = s->side[last];
}

/* The samples' brackets no wider than `tolerance` closed (a NaN width too). */
static void close_narrow(Open *s, int *count, double tolerance, double *out)
{
    for (int j = 0; j < *count;)
        if (s->high[j] - s->low[j] > tolerance)
            j++;
        else
            close_sample(s, j, count, out);
}

/* The torsion-bar torque out[i] with out + factor A(out) = y[i] at each of the n samples; `factor` NULL: 1,
 * `direction` (the gear's tanh of omega / w at each sample's rotor speed) NULL for a valve, `knots` NULL without a
 * table. The root lies between 0 and y (A has the sign of its argument); where rounding says otherwise, the bracket
 * is y -+ `width` (as wide as the assist can be; `width_known` 0: it could not be had, and the call returns -1 at
 * the first sample that needs it). Both ends' values known, an end that is the root closes the bracket; then at
 * most `iterations` steps: the secant point, or the midpoint where it falls outside the open bracket (or is NaN),
 * the end on its side moved to it, the end that stays a second time in a row with its value halved (Illinois), the
 * bracket closed on a point that is the root, until it is no wider than `tolerance`. The torque is its midpoint.
 * Blocks of LANES samples are stepped side by side, each sample's steps its own. */
int ps_torsion_bar(long n, const double *y, const double *factor, const double *direction, const double *values,
                   int hydraulic, int points, const double *knots, const double *assist, const double *slope,
                   double width, int width_known, double tolerance, int iterations, double *out)
{
    Law law = {values, hydraulic, knots ? points : 0, knots, assist, slope};
    Open s;
    double x[LANES], fx[LANES];
    const double *f = factor ? s.factor : 0, *d = direction ? s.direction : 0;
    for (long base = 0; base < n; base += LANES) {
        int count = n - base < LANES ? (int)(n - base) : LANES;
        for (int j = 0; j < count; j++) {
            double yj = y[base + j];
            s.index[j] = base + j;
            s.y[j] = yj;
            s.factor[j] = factor ? factor[base + j] : 1.0;
            s.direction[j] = direction ? direction[base + j] : 0.0;
            /* numpy's minimum and maximum: a NaN propagated, the second operand (0.0) where the two are equal */
            s.low[j] = (yj < 0.0 || yj != yj) ? yj : 0.0;
            s.high[j] = (yj > 0.0 || yj != yj) ? yj : 0.0;
            s.side[j] = 0;
        }
        excess(&law, count, s.low, s.y, f, d, s.f_low);
        excess(&law, count, s.high, s.y, f, d, s.f_high);
        for (int j = 0; j < count; j++) {
            if (s.f_low[j] > 0.0 || s.f_high[j] < 0.0) { /* rounding put the root outside [min(y, 0), max(y, 0)] */
                if (!width_known)
                    return -1;
                s.low[j] = s.y[j] - width;
                s.high[j] = s.y[j] + width;
                excess(&law, 1, s.low + j, s.y + j, f ? f + j : 0, d ? d + j : 0, s.f_low + j);
                excess(&law, 1, s.high + j, s.y + j, f ? f + j : 0, d ? d + j : 0, s.f_high + j);
            }
            if (s.f_high[j] == 0.0) /* an end that is the root */
                s.low[j] = s.high[j];
            if (s.f_low[j] == 0.0)
                s.high[j] = s.low[j];
        }
        close_narrow(&s, &count, tolerance, out);
        for (int step = 0; step < iterations && count > 0; step++) {
            for (int j = 0; j < count; j++) {
                double low = s.low[j], high = s.high[j];
                double secant = low - s.f_low[j] * (high - low) / (s.f_high[j] - s.f_low[j]);
                x[j] = (secant > low && secant < high) ? secant : 0.5 * (low + high);
            }
            excess(&law, count, x, s.y, f, d, fx);
            for (int j = 0; j < count; j++) {
                int above = fx[j] > 0.0;
                if (above && s.side[j] == 1) /* Illinois: the end that stays a second time has its value halved */
                    s.f_low[j] = 0.5 * s.f_low[j];
                if (!above && s.side[j] == -1)
                    s.f_high[j] = 0.5 * s.f_high[j];
                if (above) {
                    s.high[j] = x[j];
                    s.f_high[j] = fx[j];
                } else {
                    s.low[j] = x[j];
                    s.f_low[j] = fx[j];
                }
                s.side[j] = above ? 1 : -1;
                if (fx[j] == 0.0)
                    s.low[j] = s.high[j] = x[j];
            }
            close_narrow(&s, &count, tolerance, out);
        }
        while (count > 0) /* the step cap met */
            close_sample(&s, 0, &count, out);
    }
    return 0;
}
