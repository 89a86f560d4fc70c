/* rng.c -- ziggurat tables and the rare slow path of gr_normal (see rng.h). */
#include <math.h>

#include "rng.h"

uint32_t gr_zig_k[128];
double gr_zig_w[128], gr_zig_f[128];

int gr_rng_ready = 0;

/* Marsaglia & Tsang (2000), 128 layers: r is the start of the tail, v the area of each
 * layer.  The binding calls this once at import, before any thread can draw. */
void gr_rng_init(void)
{
    if (gr_rng_ready) return;
    const double m1 = 2147483648.0, vn = 9.91256303526217e-3;
    double dn = 3.442619855899, tn = dn;
    double q = vn / exp(-0.5 * dn * dn);
    gr_zig_k[0] = (uint32_t)((dn / q) * m1);
    gr_zig_k[1] = 0;
    gr_zig_w[0] = q / m1;
    gr_zig_w[127] = dn / m1;
    gr_zig_f[0] = 1.0;
    gr_zig_f[127] = exp(-0.5 * dn * dn);
    for (int i = 126; i >= 1; i--) {
        dn = sqrt(-2.0 * log(vn / dn + exp(-0.5 * dn * dn)));
        gr_zig_k[i + 1] = (uint32_t)((dn / tn) * m1);
        tn = dn;
        gr_zig_f[i] = exp(-0.5 * dn * dn);
        gr_zig_w[i] = dn / m1;
    }
    gr_rng_ready = 1;
}

double gr_normal_tail(gr_stream *s, int64_t hz, int iz)
{
    const double r = 3.442619855899;
    for (;;) {
        double x = hz * gr_zig_w[iz];
        if (iz == 0) { /* the tail beyond r, by Marsaglia's exponential method */
            double xx, yy;
            do {
                xx = -log(gr_uniform(s)) / r;
                yy = -log(gr_uniform(s));
            } while (yy + yy < xx * xx);
            return hz > 0 ? r + xx : -r - xx;
        }
        if (gr_zig_f[iz] + gr_uniform(s) * (gr_zig_f[iz - 1] - gr_zig_f[iz]) < exp(-0.5 * x * x))
            return x;
        uint64_t u = gr_next64(s);
        iz = (int)(u >> 57);
        hz = (int32_t)(uint32_t)u;
        uint32_t mag = hz < 0 ? (uint32_t)(-hz) : (uint32_t)hz;
        if (mag < gr_zig_k[iz]) return hz * gr_zig_w[iz];
    }
}
