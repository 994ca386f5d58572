/* A bare C velocity-Verlet (leapfrog) for the Hertz chain: the reference of
 * benchmarks/kernel.py --roofline (issue 17 item 4).
 *
 * The same equations and arithmetic as discrete/kernels.py (paper Eqs. 1-2):
 *   r_j   = d0_j + (u_{j-1} - u_j)                     overlap of contact j, m
 *   phi_j = k_j [r_j]_+ sqrt([r_j]_+) - f0_j            Hertz force minus the static one, N
 *   a_i   = (phi_i - phi_{i+1}) / m_i                   m/s^2 (u_{-1} = wl, u_N = wr)
 * with contacts j = 0..N (k_0 = 0 and/or k_N = 0 for a free end), one step being
 *   u += h v ; phi(u) ; v = (v + c1 a) + c2 a            c1 = h/2, c2 = h/2 (next step's
 *                                                        opening kick) or 0 at the end
 * after an opening kick v += (h/2) a.  On exit v is the synchronous velocity and a the
 * acceleration of the final u: the state layout of discrete.Simulation (u, v, a).
 *
 * Written the way gcc vectorises well: three flat loops per step (drift, contact forces
 * into a scratch array, kick), branch-free clip [r]_+, one sqrt per contact, restrict
 * pointers.  [r]_+ is 0.5 (r + |r|), bit for bit max(r, 0) (2r and its half are exact),
 * which gcc vectorises for AVX2 too (the ternary r > 0 ? r : 0 it leaves as a branch
 * there, and fmax needs NaN handling).  Compiled with -O3 -march=... -fno-math-errno (sqrt without the errno branch,
 * which would stop the loop vectorising; results unchanged).  With gcc's default
 * -ffp-contract=fast the products are fused into FMAs (round-off differences with the
 * numba kernel, which does not contract); with -ffp-contract=off the arithmetic is the
 * numba kernel's bit for bit (checked by benchmarks/kernel.py before timing).
 */
#include <math.h>

static void forces(long n, const double *restrict u, double *restrict f,
                   const double *restrict k, const double *restrict d0,
                   const double *restrict f0, double wl, double wr)
{
    double r = d0[0] + (wl - u[0]);
    double rp = 0.5 * (r + fabs(r));
    f[0] = k[0] * (rp * sqrt(rp)) - f0[0];
    for (long j = 1; j < n; j++) {
        r = d0[j] + (u[j - 1] - u[j]);
        rp = 0.5 * (r + fabs(r));
        f[j] = k[j] * (rp * sqrt(rp)) - f0[j];
    }
    r = d0[n] + (u[n - 1] - wr);
    rp = 0.5 * (r + fabs(r));
    f[n] = k[n] * (rp * sqrt(rp)) - f0[n];
}

/* nsteps velocity-Verlet steps of n grains; f is scratch of n + 1 doubles. */
void leapfrog(long n, long nsteps, double *restrict u, double *restrict v,
              double *restrict a, double *restrict f, const double *restrict im,
              const double *restrict k, const double *restrict d0,
              const double *restrict f0, double wl, double wr, double h)
{
    const double c1 = 0.5 * h;
    for (long i = 0; i < n; i++)
        v[i] = v[i] + c1 * a[i];
    for (long s = 0; s < nsteps; s++) {
        const double c2 = s == nsteps - 1 ? 0.0 : c1;
        for (long i = 0; i < n; i++)
            u[i] = u[i] + h * v[i];
        forces(n, u, f, k, d0, f0, wl, wr);
        for (long i = 0; i < n; i++) {
            const double ai = (f[i] - f[i + 1]) * im[i];
            const double vi = v[i] + c1 * ai;
            v[i] = vi + c2 * ai;
        }
    }
    forces(n, u, f, k, d0, f0, wl, wr);
    for (long i = 0; i < n; i++)
        a[i] = (f[i] - f[i + 1]) * im[i];
}
