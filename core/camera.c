/* camera.c: see camera.h. */
#include "camera.h"

#include <cglm/cglm.h>
#include <math.h>

rt_status camera_frame_compute(const scene_camera *camera, int width, int height, camera_frame *frame,
                               rt_error *error)
{
    if (width < 1 || height < 1)
        return rt_error_set(error, RT_ERROR_INPUT, "CAMERA: image size %dx%d is not positive", width, height);
    if (!(camera->vertical_fov_degrees > 0 && camera->vertical_fov_degrees < 180))
        return rt_error_set(error, RT_ERROR_INPUT, "CAMERA: fov %g is outside (0, 180) degrees",
                            camera->vertical_fov_degrees);
    vec3 from, at, up, w, u, v;
    glm_vec3_copy((float *)camera->look_from, from);
    glm_vec3_copy((float *)camera->look_at, at);
    glm_vec3_copy((float *)camera->up, up);
    glm_vec3_sub(from, at, w);
    float view_distance = glm_vec3_norm(w);
    if (!(view_distance > 0))
        return rt_error_set(error, RT_ERROR_INPUT, "CAMERA: look-from and look-at are the same point");
    glm_vec3_scale(w, 1.0f / view_distance, w);
    glm_vec3_cross(up, w, u);
    float u_length = glm_vec3_norm(u);
    if (!(u_length > 1e-6f * glm_vec3_norm(up)) || !(glm_vec3_norm(up) > 0))
        return rt_error_set(error, RT_ERROR_INPUT, "CAMERA: the up vector is zero or parallel to the view direction");
    glm_vec3_scale(u, 1.0f / u_length, u);
    glm_vec3_cross(w, u, v);

    float focus = camera->focus_distance > 0 ? camera->focus_distance : view_distance;
    float half_height = tanf(glm_rad(camera->vertical_fov_degrees) * 0.5f) * focus;
    float half_width = half_height * (float)width / (float)height;

    glm_vec3_copy(from, frame->origin);
    glm_vec3_copy(u, frame->u);
    glm_vec3_copy(v, frame->v);
    glm_vec3_copy(w, frame->w);
    glm_vec3_scale(u, 2 * half_width, frame->horizontal);
    glm_vec3_scale(v, 2 * half_height, frame->vertical);
    glm_vec3_copy(from, frame->lower_left);
    glm_vec3_muladds(u, -half_width, frame->lower_left);
    glm_vec3_muladds(v, -half_height, frame->lower_left);
    glm_vec3_muladds(w, -focus, frame->lower_left);
    frame->lens_radius = camera->aperture * 0.5f;
    frame->focus_distance = focus;
    return RT_OK;
}

void camera_frame_ray(const camera_frame *frame, float s, float t, float a, float b, float origin[3],
                      float direction[3])
{
    vec3 lens;
    glm_vec3_scale((float *)frame->u, a, lens);
    glm_vec3_muladds((float *)frame->v, b, lens);
    glm_vec3_copy((float *)frame->origin, origin);
    glm_vec3_muladds(lens, frame->lens_radius, origin);
    glm_vec3_copy((float *)frame->lower_left, direction);
    glm_vec3_muladds((float *)frame->horizontal, s, direction);
    glm_vec3_muladds((float *)frame->vertical, t, direction);
    glm_vec3_sub(direction, origin, direction);
    glm_vec3_normalize(direction);
}
