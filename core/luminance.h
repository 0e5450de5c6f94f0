/* luminance.h: the luminance of a colour, Y = LUMINANCE_R r + LUMINANCE_G g + LUMINANCE_B b
 * with Rec. 709's weights, which core/tracer_interface.h defines once for C and the
 * tracer's GLSL alike. The float version computes in float, as the tracer does, so that
 * what C recomputes from the tracer's means (variance.Y, adaptive sampling's error, a
 * merge's recombined variance) matches it. */
#ifndef RT_LUMINANCE_H
#define RT_LUMINANCE_H

#include "tracer_interface.h"

/* Returns the luminance of (r, g, b) in float arithmetic. */
static inline float luminance_float(float r, float g, float b)
{
    return (float)LUMINANCE_R * r + (float)LUMINANCE_G * g + (float)LUMINANCE_B * b;
}

/* Returns the luminance of (r, g, b) in double arithmetic (light powers, sums). */
static inline double luminance_double(double r, double g, double b)
{
    return LUMINANCE_R * r + LUMINANCE_G * g + LUMINANCE_B * b;
}

#endif
