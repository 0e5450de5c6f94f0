/* generator.h: what the scene generators weekend.c and next-week.c share: a reproducible
 * random stream and a number format the scene parser reads. Header-only (static functions)
 * so that each generator stays one `cc file.c -lm` away from its scene: the compiler finds
 * this header beside the source file.
 *
 * Random numbers: splitmix64 (Steele, Lea and Flood, "Fast splittable pseudorandom number
 * generators", OOPSLA 2014; the variant of Vigna's splitmix64.c) on one global state that
 * generator_seed() sets; rnd() is the top 53 bits of one 64-bit output times 2^-53, so the
 * stream is the same on every platform.
 *
 * Numbers are printed with %.6g, except that a value %.6g would print with an exponent
 * (|v| < 1e-4) is printed in fixed notation, so a scene never depends on the parser
 * reading exponents.
 */
#ifndef RTSPHERES_SCENE_GENERATOR_H
#define RTSPHERES_SCENE_GENERATOR_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

static uint64_t rng_state;

/* Starts the random stream at seed; call it once before the first rnd(). */
static void generator_seed(uint64_t seed)
{
    rng_state = seed;
}

/* The next 64-bit output of splitmix64. */
static uint64_t splitmix64(void)
{
    uint64_t z = (rng_state += UINT64_C(0x9e3779b97f4a7c15));
    z = (z ^ (z >> 30)) * UINT64_C(0xbf58476d1ce4e5b9);
    z = (z ^ (z >> 27)) * UINT64_C(0x94d049bb133111eb);
    return z ^ (z >> 31);
}

/* A double in [0, 1). */
static double rnd(void)
{
    return (double)(splitmix64() >> 11) * (1.0 / 9007199254740992.0);
}

/* Formats v like %.6g but never with an exponent; returns buf, which must hold 64 chars. */
static const char *num(char *buf, double v)
{
    snprintf(buf, 64, "%.6g", v);
    if (strchr(buf, 'e') || strchr(buf, 'E')) {
        /* Only tiny values get here (the scenes' values are all below 1e6). */
        snprintf(buf, 64, "%.12f", v);
        size_t n = strlen(buf);
        while (n > 0 && buf[n - 1] == '0')
            buf[--n] = '\0';
        if (n > 0 && buf[n - 1] == '.')
            buf[--n] = '\0';
        if (strcmp(buf, "-0") == 0 || n == 0)
            strcpy(buf, "0");
    }
    return buf;
}

#endif
