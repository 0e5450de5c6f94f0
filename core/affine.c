/* affine.c: see affine.h (why double, the layout of a map). */
#include "affine.h"

#include <math.h>

affine affine_identity(void)
{
    affine identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    return identity;
}

affine affine_translation(const double offset[3])
{
    affine translation = affine_identity();
    for (int i = 0; i < 3; i++)
        translation.m[i][3] = offset[i];
    return translation;
}

affine affine_scale(const double factors[3])
{
    affine scale = affine_identity();
    for (int i = 0; i < 3; i++)
        scale.m[i][i] = factors[i];
    return scale;
}

affine affine_rotation(const double axis[3], double degrees)
{
    double radians = degrees * (3.14159265358979323846 / 180.0);
    double c = cos(radians), s = sin(radians), t = 1 - c;
    double x = axis[0], y = axis[1], z = axis[2];
    affine rotation = {{
        {t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0},
        {t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0},
        {t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0},
    }};
    return rotation;
}

affine affine_compose(const affine *outer, const affine *inner)
{
    affine result;
    for (int row = 0; row < 3; row++) {
        for (int column = 0; column < 4; column++) {
            double sum = column == 3 ? outer->m[row][3] : 0;
            for (int k = 0; k < 3; k++)
                sum += outer->m[row][k] * inner->m[k][column];
            result.m[row][column] = sum;
        }
    }
    return result;
}

double affine_determinant(const affine *a)
{
    const double (*m)[4] = a->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

void vector_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

double vector_length(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

bool vector_normalise(const double v[3], double unit[3])
{
    double largest = fmax(fabs(v[0]), fmax(fabs(v[1]), fabs(v[2])));
    if (largest == 0)
        return false;
    double scaled[3];
    for (int i = 0; i < 3; i++)
        scaled[i] = v[i] / largest;
    double length = vector_length(scaled);
    for (int i = 0; i < 3; i++)
        unit[i] = scaled[i] / length;
    return true;
}

bool vector_normalise_to_float(const double v[3], float unit[3])
{
    double exact[3];
    if (!vector_normalise(v, exact))
        return false;
    for (int i = 0; i < 3; i++)
        unit[i] = (float)exact[i];
    return true;
}

bool vectors_parallel(const double a[3], const double b[3])
{
    double cross[3];
    vector_cross(a, b, cross);
    /* Written as "not greater" so that a zero vector (0 > 0 is false) counts as parallel. */
    return !(vector_length(cross) > 1e-6 * vector_length(a) * vector_length(b));
}
