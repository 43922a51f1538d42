/*
 * View directions for a fit (issue 27): a Fibonacci lattice on the sphere
 * (Gonzalez 2010, "Measurement of areas on a sphere using Fibonacci and
 * latitude-longitude lattices"): n points of equal area, no clustering at the
 * poles, rotated about the up axis by a seeded angle so that training and
 * held-out sets differ.
 */
#include <math.h>

#include "amgsplat/fit.h"
#include "util/banned.h"

void asp_fit_directions(size_t n, uint64_t seed, float *azimuth, float *elevation)
{
    const double pi = 3.14159265358979323846;
    const double golden = pi * (3.0 - sqrt(5.0)); // the golden angle
    // splitmix64 of the seed: a rotation in [0, 2 pi) that any seed spreads well
    uint64_t z = seed + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    double rot = 2.0 * pi * (double)(z >> 11) / 9007199254740992.0;
    for (size_t i = 0; i < n; i++) {
        double y = 1.0 - (2.0 * (double)i + 1.0) / (double)n; // cell centres: never exactly a pole
        double phi = rot + golden * (double)i;
        elevation[i] = (float)(asin(y) * 180.0 / pi);
        azimuth[i] = (float)(fmod(phi, 2.0 * pi) * 180.0 / pi);
    }
}
