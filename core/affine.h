/* affine.h: affine maps and 3-vectors in double precision, the scene parser's maths.
 *
 * Why double: a transform statement's numbers come from the expression evaluator in
 * double, and a placement composes the transforms of every block around it (groups in
 * groups, instances of groups of instances): composed in float, the rounding of each
 * step would add up, and the same object reached by two paths would land at two places.
 * So the parser composes in double and rounds to float once, when a placement becomes
 * a scene_instance (core/scene_builder.c). The checks that decide whether a direction
 * exists (zero vectors, parallel edges, a camera's up along its view) use the same
 * functions, so every part of the parser (core/scene_*.c) tests them one way. The
 * renderer's own maths is float (core/camera.c with cglm, the packer's core/pack_*.c);
 * nothing here is for it.
 *
 * An affine map is p' = m[:, 0..2] p + m[:, 3], rows x, y, z: the layout of
 * scene_instance.object_to_world. Every function is pure: it reads its arguments and
 * writes only its result; nothing allocates or fails.
 */
#ifndef RT_AFFINE_H
#define RT_AFFINE_H

#include <stdbool.h>

typedef struct affine {
    double m[3][4];
} affine;

/* Returns the map that leaves every point where it is. */
affine affine_identity(void);

/* Returns the translation by offset. */
affine affine_translation(const double offset[3]);

/* Returns the scale about the origin by factors along x, y and z. */
affine affine_scale(const double factors[3]);

/* Returns the right-handed rotation by degrees about the unit vector axis through the
 * origin (Rodrigues' formula). */
affine affine_rotation(const double axis[3], double degrees);

/* Returns outer ∘ inner: inner applies first. */
affine affine_compose(const affine *outer, const affine *inner);

/* Returns the determinant of the 3x3 (linear) part; 0 for a map that flattens space. */
double affine_determinant(const affine *a);

/* Writes a x b to out (which may not be a or b). */
void vector_cross(const double a[3], const double b[3], double out[3]);

/* Returns the Euclidean length of v. */
double vector_length(const double v[3]);

/* Scales v to unit length into unit, dividing by its largest component first so that
 * tiny vectors do not underflow. Returns false (unit untouched) when v is zero, which
 * has no direction. */
bool vector_normalise(const double v[3], double unit[3]);

/* The same, rounded to float once at the end (a light's direction, a shading normal). */
bool vector_normalise_to_float(const double v[3], float unit[3]);

/* True when a and b are parallel, or either is zero: the sine of the angle between them
 * is at most 1e-6, well above float rounding (a relative test, so it does not depend on
 * the vectors' lengths). */
bool vectors_parallel(const double a[3], const double b[3]);

#endif
