/* metadata_keys.h: the names of the rtspheres:* metadata in the EXR files rtspheres writes,
 * spelled once. The writer is core/render_output.c (for renders, their partial files and
 * merges); the readers are core/merge.c (merge_read_part), core/render_output.c (resuming
 * a partial), core/relight.c, cli/command_stats.c and render_output_derived_metadata()
 * (core/render_output.c, which copies them into what denoise and relight make).
 *
 *   key               type      what it says
 *   version           string    the rtspheres version that wrote the file
 *   scene             string    the scene file's path, as given
 *   scene_hash        string    render_result.scene_hash as 16 hex digits
 *   spp               int       the samples per pixel asked for (a merge: the fewest any
 *                               pixel has)
 *   sample_start      text      the first sample index (decimal; may pass 2^31)
 *   seed              text      the random seed (decimal)
 *   max_depth         int       path segments per sample at most
 *   frame             int       the frame number, -1 without --frames
 *   samples_finished  text      samples finished over all pixels (decimal)
 *   path_segments     text      rays traced (decimal)
 *   complete          int       1 when the render ended by its own rule (every sample asked
 *                               for ran, or adaptive sampling stopped every pixel), else 0
 *   stop_reason       string    why the passes ended (render.h render_stop_reason): spp,
 *                               noise (adaptive sampling), time (--time-limit) or
 *                               interrupted; renders and partials only, not merges
 *   noise_threshold   float     --noise-threshold (0: no adaptive sampling); renders only
 *   min_spp           int       --min-spp as used (0 without adaptive sampling); renders only
 *   render_seconds    float     the render's time (a merge: summed over its parts)
 *   merged_parts      int       only in a merge's output: how many parts it merged
 *   options_hash      string    render_job_options_hash() as 16 hex digits: the options that
 *                               change the pixels beyond the scene hash (render_job.h says
 *                               which); renders and partials only. --skip-existing compares it
 *   light_groups      string    only with light group layers (--light-groups, relight): the
 *                               groups' names, comma-separated; group NAME's layer is the
 *                               channels NAME.R, NAME.G, NAME.B
 *   postprocess       string    only in an image whose colour is no longer the render's
 *                               means: what changed it, in order, "; "-separated: "denoise"
 *                               (render --denoise, rtspheres denoise), "blur sigma=S passes=N"
 *                               (render --blur), "relight NAME=W ..." (rtspheres relight,
 *                               each --group as given, normalised). Such a file is refused
 *                               as a merge part. rtspheres denoise and relight carry every
 *                               other key of their input into their output but
 *                               options_hash (render_output.h render_output_derived_metadata)
 * "text" values are whole numbers stored as decimal text, since an OpenEXR int attribute
 * holds 32 bits only.
 */
#ifndef RT_METADATA_KEYS_H
#define RT_METADATA_KEYS_H

#define METADATA_KEY_VERSION "rtspheres:version"
#define METADATA_KEY_SCENE "rtspheres:scene"
#define METADATA_KEY_SCENE_HASH "rtspheres:scene_hash"
#define METADATA_KEY_SPP "rtspheres:spp"
#define METADATA_KEY_SAMPLE_START "rtspheres:sample_start"
#define METADATA_KEY_SEED "rtspheres:seed"
#define METADATA_KEY_MAX_DEPTH "rtspheres:max_depth"
#define METADATA_KEY_FRAME "rtspheres:frame"
#define METADATA_KEY_SAMPLES_FINISHED "rtspheres:samples_finished"
#define METADATA_KEY_PATH_SEGMENTS "rtspheres:path_segments"
#define METADATA_KEY_COMPLETE "rtspheres:complete"
#define METADATA_KEY_RENDER_SECONDS "rtspheres:render_seconds"
#define METADATA_KEY_MERGED_PARTS "rtspheres:merged_parts"
#define METADATA_KEY_STOP_REASON "rtspheres:stop_reason"
#define METADATA_KEY_NOISE_THRESHOLD "rtspheres:noise_threshold"
#define METADATA_KEY_MIN_SPP "rtspheres:min_spp"
#define METADATA_KEY_LIGHT_GROUPS "rtspheres:light_groups"
#define METADATA_KEY_OPTIONS_HASH "rtspheres:options_hash"
#define METADATA_KEY_POSTPROCESS "rtspheres:postprocess"

/* Every key, in the order `rtspheres stats` prints them: an initializer for an array of
 * METADATA_KEY_COUNT strings. */
#define METADATA_KEY_COUNT 19
#define METADATA_KEYS_IN_STATS_ORDER                                                                         \
    {                                                                                                        \
        METADATA_KEY_VERSION, METADATA_KEY_SCENE, METADATA_KEY_SCENE_HASH, METADATA_KEY_OPTIONS_HASH,          \
            METADATA_KEY_FRAME, METADATA_KEY_SPP,                                                             \
            METADATA_KEY_SEED, METADATA_KEY_MAX_DEPTH, METADATA_KEY_SAMPLE_START, METADATA_KEY_SAMPLES_FINISHED, \
            METADATA_KEY_PATH_SEGMENTS, METADATA_KEY_COMPLETE, METADATA_KEY_STOP_REASON,                      \
            METADATA_KEY_NOISE_THRESHOLD, METADATA_KEY_MIN_SPP, METADATA_KEY_RENDER_SECONDS,                 \
            METADATA_KEY_MERGED_PARTS, METADATA_KEY_LIGHT_GROUPS, METADATA_KEY_POSTPROCESS,                  \
    }

#endif
