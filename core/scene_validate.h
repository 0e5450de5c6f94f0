/* scene_validate.h: the scene parser's validation pass (internal to the parser): the
 * checks that need the whole file, run once it is read and built (core/scene_parse.c).
 *
 * In this order, each failing with one message (scene_report.h):
 *   1. every -D define that is not optional is set or used by the scene (a typo would
 *      otherwise silently do nothing);
 *   2. the camera's final from/at/up (clauses may come from several camera statements)
 *      make a frame: from differs from at, and up is not parallel to the view direction
 *      (reported at the last camera statement);
 *   3. every surface has a material: a shape without its own takes its instance's;
 *   4. a volume's boundary is not an obviously open surface (1 to 3 flat faces).
 * It only reads the builder, the variables and the options.
 */
#ifndef RT_SCENE_VALIDATE_H
#define RT_SCENE_VALIDATE_H

#include <stdbool.h>

#include "scene_builder.h"
#include "scene_parse.h"
#include "scene_values.h"

/* Runs the checks above over what builder built; returns false after reporting the
 * first failure to report. */
bool validate_scene(const scene_builder *builder, const scene_variables *variables,
                    const scene_parse_options *options, scene_report *report);

#endif
