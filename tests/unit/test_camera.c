/* test_camera.c: the camera frame (camera.h): framing, field of view, aspect, thin lens,
 * and every degenerate camera. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "camera.h"

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static scene_camera example_camera(void)
{
    scene s;
    scene_defaults(&s);
    scene_camera camera = s.camera;
    float from[3] = {13, 2, 3}, at[3] = {0, 0, 0};
    memcpy(camera.look_from, from, sizeof from);
    memcpy(camera.look_at, at, sizeof at);
    camera.vertical_fov_degrees = 20;
    return camera;
}

static void center_ray_looks_at_target(void **state)
{
    (void)state;
    scene_camera camera = example_camera();
    camera_frame frame;
    assert_int_equal(camera_frame_compute(&camera, 160, 90, &frame, NULL), RT_OK);
    float origin[3], direction[3];
    camera_frame_ray(&frame, 0.5f, 0.5f, 0, 0, origin, direction);
    float expected[3] = {-13, -2, -3};
    float length = sqrtf(dot3(expected, expected));
    for (int i = 0; i < 3; i++) {
        assert_float_equal(origin[i], camera.look_from[i], 1e-6);
        assert_float_equal(direction[i], expected[i] / length, 1e-5);
    }
}

static void vertical_fov_and_aspect(void **state)
{
    (void)state;
    scene_camera camera = example_camera();
    camera_frame frame;
    assert_int_equal(camera_frame_compute(&camera, 320, 90, &frame, NULL), RT_OK);
    float origin[3], top[3], bottom[3], left[3], right[3];
    camera_frame_ray(&frame, 0.5f, 1.0f, 0, 0, origin, top);
    camera_frame_ray(&frame, 0.5f, 0.0f, 0, 0, origin, bottom);
    camera_frame_ray(&frame, 0.0f, 0.5f, 0, 0, origin, left);
    camera_frame_ray(&frame, 1.0f, 0.5f, 0, 0, origin, right);
    float vertical_angle = acosf(dot3(top, bottom)) * 180.0f / (float)M_PI;
    assert_float_equal(vertical_angle, 20.0, 1e-3);
    /* Horizontal half-angle: tan(h/2) = aspect * tan(v/2). */
    float horizontal_angle = acosf(dot3(left, right)) * 180.0f / (float)M_PI;
    float expected = 2.0f * atanf(320.0f / 90.0f * tanf(10.0f * (float)M_PI / 180.0f)) * 180.0f / (float)M_PI;
    assert_float_equal(horizontal_angle, expected, 1e-3);
    /* The top of the image is towards "up", the right towards u. */
    assert_true(top[1] > bottom[1]);
    assert_true(dot3(right, frame.u) > dot3(left, frame.u));
}

static void basis_is_orthonormal(void **state)
{
    (void)state;
    scene_camera camera = example_camera();
    camera.up[0] = 0.3f; /* an up vector that is not perpendicular to the view */
    camera_frame frame;
    assert_int_equal(camera_frame_compute(&camera, 64, 64, &frame, NULL), RT_OK);
    assert_float_equal(dot3(frame.u, frame.u), 1, 1e-6);
    assert_float_equal(dot3(frame.v, frame.v), 1, 1e-6);
    assert_float_equal(dot3(frame.w, frame.w), 1, 1e-6);
    assert_float_equal(dot3(frame.u, frame.v), 0, 1e-6);
    assert_float_equal(dot3(frame.u, frame.w), 0, 1e-6);
    assert_float_equal(dot3(frame.v, frame.w), 0, 1e-6);
}

static void thin_lens_rays_meet_on_focus_plane(void **state)
{
    (void)state;
    scene_camera camera = example_camera();
    camera.aperture = 0.5f;
    camera.focus_distance = 10;
    camera_frame frame;
    assert_int_equal(camera_frame_compute(&camera, 100, 50, &frame, NULL), RT_OK);
    assert_float_equal(frame.lens_radius, 0.25, 1e-7);
    float lens_samples[3][2] = {{0, 0}, {1, 0}, {-0.6f, 0.7f}};
    float meeting[3][3];
    for (int k = 0; k < 3; k++) {
        float origin[3], direction[3];
        camera_frame_ray(&frame, 0.3f, 0.8f, lens_samples[k][0], lens_samples[k][1], origin, direction);
        /* Intersect with the focus plane: distance 10 along -w from look_from. */
        float to_plane = (dot3(frame.origin, frame.w) - 10.0f - dot3(origin, frame.w)) / dot3(direction, frame.w);
        for (int i = 0; i < 3; i++)
            meeting[k][i] = origin[i] + to_plane * direction[i];
    }
    for (int k = 1; k < 3; k++)
        for (int i = 0; i < 3; i++)
            assert_float_equal(meeting[k][i], meeting[0][i], 1e-4);
}

static void focus_distance_defaults_to_target_distance(void **state)
{
    (void)state;
    scene_camera camera = example_camera();
    camera_frame frame;
    assert_int_equal(camera_frame_compute(&camera, 10, 10, &frame, NULL), RT_OK);
    assert_float_equal(frame.focus_distance, sqrtf(13 * 13 + 2 * 2 + 3 * 3), 1e-5);
}

static void degenerate_cameras_are_errors(void **state)
{
    (void)state;
    camera_frame frame;
    rt_error error;
    scene_camera camera = example_camera();
    memcpy(camera.look_at, camera.look_from, sizeof camera.look_at);
    assert_int_equal(camera_frame_compute(&camera, 10, 10, &frame, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "same point"));

    camera = example_camera();
    float parallel_up[3] = {13, 2, 3};
    memcpy(camera.up, parallel_up, sizeof parallel_up);
    assert_int_equal(camera_frame_compute(&camera, 10, 10, &frame, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "parallel"));

    camera = example_camera();
    memset(camera.up, 0, sizeof camera.up);
    assert_int_equal(camera_frame_compute(&camera, 10, 10, &frame, &error), RT_ERROR_INPUT);

    camera = example_camera();
    camera.vertical_fov_degrees = 180;
    assert_int_equal(camera_frame_compute(&camera, 10, 10, &frame, &error), RT_ERROR_INPUT);
    assert_non_null(strstr(error.message, "fov"));
    camera.vertical_fov_degrees = 0;
    assert_int_equal(camera_frame_compute(&camera, 10, 10, &frame, &error), RT_ERROR_INPUT);

    camera = example_camera();
    assert_int_equal(camera_frame_compute(&camera, 0, 10, &frame, &error), RT_ERROR_INPUT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(center_ray_looks_at_target),
        cmocka_unit_test(vertical_fov_and_aspect),
        cmocka_unit_test(basis_is_orthonormal),
        cmocka_unit_test(thin_lens_rays_meet_on_focus_plane),
        cmocka_unit_test(focus_distance_defaults_to_target_distance),
        cmocka_unit_test(degenerate_cameras_are_errors),
    };
    return cmocka_run_group_tests_name("camera", tests, NULL, NULL);
}
