/* camera.h: turns the scene's look-from/look-at camera into the vectors the tracer
 * uses to make primary rays (plain C, tested without a GPU).
 *
 * A primary ray for film position (s, t) in [0,1]^2 (s right, t up; (0,0) is the
 * image's bottom-left corner) and lens sample (a, b) in the unit disk is
 *   origin    = frame.origin + lens_radius * (a * frame.u + b * frame.v)
 *   direction = frame.lower_left + s * frame.horizontal + t * frame.vertical - origin
 * so every ray through the same film point meets on the focus plane (thin lens).
 */
#ifndef RT_CAMERA_H
#define RT_CAMERA_H

#include "scene.h"
#include "status.h"

typedef struct camera_frame {
    float origin[3];
    float lower_left[3];         /* bottom-left corner of the image on the focus plane */
    float horizontal[3];         /* focus-plane vector spanning the image width */
    float vertical[3];           /* focus-plane vector spanning the image height */
    float u[3], v[3], w[3];      /* right, up, backwards (unit, orthonormal) */
    float lens_radius;
    float focus_distance;
} camera_frame;

/* Computes the frame for an image of width x height pixels. Returns RT_ERROR_INPUT when
 * the camera is degenerate (look_from == look_at, up parallel to the view, fov outside
 * (0,180), non-positive size). */
rt_status camera_frame_compute(const scene_camera *camera, int width, int height, camera_frame *frame,
                               rt_error *error);

/* The ray for film position (s, t) and lens sample (a, b), as defined above; direction
 * is normalised. */
void camera_frame_ray(const camera_frame *frame, float s, float t, float a, float b, float origin[3],
                      float direction[3]);

#endif
