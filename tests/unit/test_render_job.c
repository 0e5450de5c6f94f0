/* test_render_job.c: render jobs (render_job.h) and the files they write (render_output.h):
 * the rules between a job's fields, with their messages; which frames a shard renders;
 * output and partial names; each image's samples and region (sample ranges, shards of
 * samples and tiles, crops); the scene variables of a frame; the metadata written and read
 * back; and running jobs up to the point where a GPU would be needed (a refused plan, a
 * bad scene, an empty shard, a wrong partial, a stop between frames), then one small job
 * rendered for real on the device. */
#include "image_io.h"
#include "merge.h"
#include "metadata_keys.h"
#include "render_job.h"
#include "render_output.h"
#include "support.h"

#include <unistd.h>

/* The scratch directory of this run (support.h's, one for the whole group), with a scene
 * file in it. */
static scratch *work;
static char scene_path[300];

static const char *const scene_text = "camera from 0 0 3 at 0 0 0 up 0 1 0 fov 40\n"
                                      "material m lambertian 0.5 0.5 0.5\n"
                                      "sphere 0 0 0 1 m\n"
                                      "render size 8 6 spp 4 depth 3 seed 3\n";

/* Returns scratch/name in a rotating buffer (four names may be in use at once, which
 * support.h's in_scratch does not allow). */
static const char *job_path(const char *name)
{
    static char paths[4][512];
    static int next;
    char *path = paths[next++ % 4];
    snprintf(path, sizeof paths[0], "%s/%s", work->directory, name);
    return path;
}

/* cmocka group setup: support.h's make_scratch, then the scene file; returns 0, or -1. */
static int make_job_scratch(void **state)
{
    if (make_scratch(state) != 0)
        return -1;
    work = *state;
    snprintf(scene_path, sizeof scene_path, "%s/scene.txt", work->directory);
    FILE *file = fopen(scene_path, "w");
    if (file == NULL)
        return -1;
    fputs(scene_text, file);
    fclose(file);
    return 0;
}

/* A job rendering the scratch scene to scratch/name. */
static render_job job_for(const char *name)
{
    render_job job = render_job_defaults();
    job.scene_path = scene_path;
    job.output = job_path(name);
    return job;
}

/* A job rendering frames[0 .. count-1] of the scratch scene to the pattern scratch/name. */
static render_job frames_job_for(const char *name, const int *frames, int count)
{
    render_job job = job_for(name);
    job.frames = frames;
    job.frame_count = count;
    return job;
}

/* Checks that render_job_check() accepts job and that its first output is scratch/name. */
static void first_output_is(const render_job *job, const char *name)
{
    render_job_plan plan;
    assert_int_equal(render_job_check(job, &plan, NULL), RT_OK);
    assert_string_equal(plan.first_output, job_path(name));
}

/* Checks that render_job_check() refuses job with exactly message. */
static void refused(const render_job *job, const char *message)
{
    render_job_plan plan;
    rt_error error = {{0}};
    assert_int_equal(render_job_check(job, &plan, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, message);
}

/* The settings of a 40x30 scene with 10 samples per pixel. */
static const scene_render_settings scene_settings = {
    .width = 40, .height = 30, .samples_per_pixel = 10, .max_depth = 5, .seed = 1};

/* Checks job, then plans its image of frame from settings into *image. Returns the
 * planning's status; its message goes to error (may be NULL). */
static rt_status plan_one(const render_job *job, const scene_render_settings *settings, int frame,
                          render_job_image *image, rt_error *error)
{
    render_job_plan plan;
    assert_int_equal(render_job_check(job, &plan, NULL), RT_OK);
    return render_job_plan_image(job, &plan, settings, frame, image, error);
}

/* Checks that planning job's image from settings is refused with exactly message. */
static void image_refused(const render_job *job, const scene_render_settings *settings, const char *message)
{
    render_job_image image;
    rt_error error = {{0}};
    assert_int_equal(plan_one(job, settings, -1, &image, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, message);
}

/* The options hash (--skip-existing) of job's one image planned from settings. */
static uint64_t options_hash_of(const render_job *job, const scene_render_settings *settings)
{
    render_job_image image;
    assert_int_equal(plan_one(job, settings, -1, &image, NULL), RT_OK);
    return render_job_options_hash(job, &image, settings);
}

/* The options that change pixels change the hash; those that do not (time limit,
 * checkpoints, pass budget, the full tracer, skip_existing itself) leave it alone. */
static void options_hash(void **state)
{
    (void)state;
    render_job base = job_for("hash.exr");
    uint64_t hash = options_hash_of(&base, &scene_settings);
    assert_true(hash == options_hash_of(&base, &scene_settings));
    scene_render_settings other = scene_settings;
    other.samples_per_pixel = 11;
    assert_true(hash != options_hash_of(&base, &other));
    other = scene_settings;
    other.seed = 2;
    assert_true(hash != options_hash_of(&base, &other));
    other = scene_settings;
    other.width = 41;
    assert_true(hash != options_hash_of(&base, &other));
    render_job changed = base;
    changed.crop[2] = 20, changed.crop[3] = 10;
    assert_true(hash != options_hash_of(&changed, &scene_settings));
    changed = base;
    changed.sample_start = 2, changed.sample_count = 4;
    assert_true(hash != options_hash_of(&changed, &scene_settings));
    changed = base;
    changed.tracer.sampler = 1;
    assert_true(hash != options_hash_of(&changed, &scene_settings));
    changed = base;
    changed.tracer.noise_threshold = 0.05f;
    assert_true(hash != options_hash_of(&changed, &scene_settings));
    changed = base;
    changed.denoise = true;
    assert_true(hash != options_hash_of(&changed, &scene_settings));
    changed = base;
    changed.exposure = 1;
    assert_true(hash != options_hash_of(&changed, &scene_settings));
    changed = base;
    changed.time_limit_seconds = 5;
    changed.checkpoint_seconds = 10;
    changed.tracer.pass_work_budget = 100;
    changed.tracer.full_tracer = true;
    changed.skip_existing = true;
    assert_true(hash == options_hash_of(&changed, &scene_settings));
    changed = base;
    changed.skip_existing = true;
    changed.resume_path = "x.partial.exr";
    refused(&changed, "--skip-existing finds and resumes each image's partial file itself; not with --resume");
}

static void defaults_are_zero(void **state)
{
    (void)state;
    render_job job = render_job_defaults(), zero;
    memset(&zero, 0, sizeof zero);
    assert_memory_equal(&job, &zero, sizeof job);
    assert_string_equal(render_job_shard_kind_name(RENDER_SHARD_FRAMES), "frames");
    assert_string_equal(render_job_shard_kind_name(RENDER_SHARD_SAMPLES), "samples");
    assert_string_equal(render_job_shard_kind_name(RENDER_SHARD_TILES), "tiles");
}

static void output_names(void **state)
{
    (void)state;
    /* Without frames the pattern gets the last -D frame, else 0. */
    render_job job = job_for("f-%03d.exr");
    first_output_is(&job, "f-000.exr");
    scene_define defines[] = {{.name = "frame", .value = "3"}, {.name = "x", .value = "1"}, {.name = "frame", .value = "2*4"}};
    job.defines = defines;
    job.define_count = 3;
    first_output_is(&job, "f-008.exr");
    render_job_plan plan;
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    assert_string_equal(plan.frame_define, "2*4");
    /* With frames, the first frame's name; every frame gets its own. */
    int frames[] = {12, 5};
    job = frames_job_for("f-%03d.exr", frames, 2);
    first_output_is(&job, "f-012.exr");
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    char name[RENDER_JOB_PATH_MAX];
    assert_int_equal(render_job_output_name(&job, &plan, 5, name, sizeof name, NULL), RT_OK);
    assert_string_equal(name, job_path("f-005.exr"));
    /* One frame may go without a frame number in the name. */
    job = frames_job_for("still.png", frames, 1);
    first_output_is(&job, "still.png");
    /* The partial file sits beside the output, whatever its format. */
    char partial[RENDER_JOB_PATH_MAX];
    render_output_partial_path("out/frame-7.png", partial, sizeof partial);
    assert_string_equal(partial, "out/frame-7.partial.exr");
    render_output_partial_path("a.b/c", partial, sizeof partial);
    assert_string_equal(partial, "a.b/c.partial.exr");
}

/* --camera is a glTF scene's, and a glTF scene takes no -D (but --frames' $frame). */
static void gltf_scene_rules(void **state)
{
    (void)state;
    char message[1024];
    render_job job = job_for("out.png");
    job.camera = "front";
    snprintf(message, sizeof message, "--camera picks a camera of a glTF file (.gltf, .glb); '%s' is a scene file, "
             "whose camera statement sets the camera", scene_path);
    refused(&job, message);
    job.scene_path = "model.glb";
    first_output_is(&job, "out.png");
    scene_define define = {.name = "size", .value = "2"};
    job.defines = &define;
    job.define_count = 1;
    refused(&job, "-D size: a glTF scene ('model.glb') has no variables");
    define.optional = true;
    first_output_is(&job, "out.png");
}

static void output_rules(void **state)
{
    (void)state;
    char message[1024];
    int frames[] = {1, 2};
    scene_define frame_define = {.name = "frame", .value = "3"}, time_define = {.name = "time", .value = "0.5"};
    render_job job = frames_job_for("f-%d.png", frames, 2);
    job.defines = &frame_define;
    job.define_count = 1;
    refused(&job, "-D frame and --frames both set $frame (--frames sets $frame and $time); give one");
    job.defines = &time_define;
    refused(&job, "-D time and --frames both set $time (--frames sets $frame and $time); give one");
    job = frames_job_for("f.png", frames, 2);
    snprintf(message, sizeof message,
             "2 frames would all write '%s'; put a frame number pattern in the output, e.g. frame-%%04d.png",
             job_path("f.png"));
    refused(&job, message);
    job = job_for("f-%d-%d.png");
    snprintf(message, sizeof message,
             "output '%s': use exactly one %%d-style conversion (e.g. frame-%%04d.png) and %%%% for a percent sign",
             job_path("f-%d-%d.png"));
    refused(&job, message);
    job = job_for("f.bmp");
    snprintf(message, sizeof message, "cannot tell the format of '%s'; use .exr, .hdr, .png, .jpg or .tif",
             job_path("f.bmp"));
    refused(&job, message);
    job = job_for("missing/f.png");
    snprintf(message, sizeof message, "cannot write '%s': its directory does not exist or is not writable",
             job_path("missing/f.png"));
    refused(&job, message);
    /* The scene file is never an output, however it is spelled. */
    char scene_png[512];
    snprintf(scene_png, sizeof scene_png, "%s", write_file(work, "scene.png", scene_text));
    job = job_for("./scene.png");
    job.scene_path = scene_png;
    snprintf(message, sizeof message, "the output '%s' is the scene file; refusing to overwrite it",
             job_path("./scene.png"));
    refused(&job, message);
    unlink(scene_png);
}

static void part_rules(void **state)
{
    (void)state;
    char message[1024];
    int frames[] = {1, 2, 3};
    render_job job = job_for("a.png");
    job.crop[2] = job.crop[3] = 4;
    job.tile_count = 2;
    job.aovs = true;
    refused(&job, "--crop and --tile both choose the region; give one");  /* the first rule broken wins */
    job = job_for("a.png");
    job.aovs = true;
    snprintf(message, sizeof message, "--aovs writes extra layers, which only .exr keeps; not '%s'",
             job_path("a.png"));
    refused(&job, message);
    job = frames_job_for("a-%d.exr", frames, 2);
    job.resume_path = "x.exr";
    refused(&job, "--resume continues one image; render the frames one at a time");
    job = job_for("a.exr");
    job.shard_by = RENDER_SHARD_SAMPLES;
    refused(&job, "--shard-by samples does nothing without --shard I/N");
    job.shard_count = 2;
    job.shard_by = RENDER_SHARD_FRAMES;
    refused(&job, "--shard-by frames needs --frames");
    job = frames_job_for("a-%d.exr", frames, 3);
    job.shard_index = 3;
    job.shard_count = 4;
    refused(&job, "shard 3/4 of 3 frames is empty; use fewer shards");
    job.frame_count = 1;
    job.shard_index = 1;
    job.shard_by = RENDER_SHARD_FRAMES;
    refused(&job, "shard 1/4 of 1 frame is empty; use fewer shards");
    job = job_for("a.exr");
    job.shard_count = 2;
    job.sample_count = 4;
    refused(&job, "--shard by samples and --samples both choose the samples; give one");
    job.sample_count = 0;
    job.shard_by = RENDER_SHARD_TILES;
    job.crop[2] = job.crop[3] = 2;
    refused(&job, "--shard by tiles and --crop/--tile both choose the region; give one");
    memset(job.crop, 0, sizeof job.crop);
    job.tile_count = 2;
    refused(&job, "--shard by tiles and --crop/--tile both choose the region; give one");

    /* Adaptive sampling: parts of the samples would each stop on their own samples. */
    job = job_for("a.exr");
    job.tracer.min_spp = 8;
    refused(&job, "--min-spp does nothing without --noise-threshold");
    job.tracer.noise_threshold = 0.05f;
    job.shard_count = 2;
    refused(&job, "--noise-threshold cannot be combined with --shard-by samples: each part would stop its pixels "
                  "on its own samples; shard by tiles or frames");
    job.shard_by = RENDER_SHARD_TILES;
    render_job_plan plan;
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    job.shard_count = 0;
    job.shard_by = RENDER_SHARD_AUTO;
    job.sample_count = 8;
    refused(&job, "--noise-threshold cannot be combined with --samples: each part would stop its pixels on its "
                  "own samples; render all samples, or split by --tile or --crop");
    job.sample_count = 0;
    /* Resuming: the whole image (its partial keeps the adaptive state), not a part of it. */
    job.resume_path = "a.partial.exr";
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    job.crop[2] = job.crop[3] = 2;
    refused(&job, "--noise-threshold cannot --resume part of an image (--crop, --tile, --shard-by tiles): its "
                  "pixels' decisions depend on pixels past the part, which the partial file does not hold; render "
                  "the part afresh");
}

static void shards(void **state)
{
    (void)state;
    render_job_plan plan;
    int frames[] = {10, 11, 12, 13, 14, 15, 16};
    /* Several frames: a shard is by frames unless told otherwise; position i % N == I. */
    render_job job = frames_job_for("f-%d.exr", frames, 7);
    job.shard_index = 1;
    job.shard_count = 3;
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    assert_int_equal(plan.shard_by, RENDER_SHARD_FRAMES);
    bool expected[7] = {false, true, false, false, true, false, false};
    for (int i = 0; i < 7; i++)
        assert_int_equal(render_job_includes_frame(&job, &plan, i), expected[i]);
    /* One frame, or none: by samples, and every frame is rendered. */
    job.frame_count = 1;
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    assert_int_equal(plan.shard_by, RENDER_SHARD_SAMPLES);
    assert_true(render_job_includes_frame(&job, &plan, 0));
    job = job_for("a.exr");
    job.shard_count = 2;
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    assert_int_equal(plan.shard_by, RENDER_SHARD_SAMPLES);
    assert_int_equal(plan.tile_count, 0);
    /* By tiles: the shard is the tile. */
    job.shard_index = 1;
    job.shard_by = RENDER_SHARD_TILES;
    assert_int_equal(render_job_check(&job, &plan, NULL), RT_OK);
    assert_int_equal(plan.tile_index, 1);
    assert_int_equal(plan.tile_count, 2);
}

static void image_samples(void **state)
{
    (void)state;
    render_job_image image;
    render_job job = job_for("a.exr");
    assert_int_equal(plan_one(&job, &scene_settings, -1, &image, NULL), RT_OK);
    assert_int_equal(image.frame, -1);
    assert_int_equal(image.sample_start, 0);
    assert_int_equal(image.samples_per_pixel, 10);
    /* A sample range is taken as it is. */
    job.sample_start = 100;
    job.sample_count = 7;
    assert_int_equal(plan_one(&job, &scene_settings, 4, &image, NULL), RT_OK);
    assert_int_equal(image.frame, 4);
    assert_int_equal(image.sample_start, 100);
    assert_int_equal(image.samples_per_pixel, 7);
    /* Shards of the samples are contiguous and cover every sample once. */
    job = job_for("a.exr");
    job.shard_count = 4;
    uint32_t next = 0;
    for (int i = 0; i < 4; i++) {
        job.shard_index = i;
        assert_int_equal(plan_one(&job, &scene_settings, -1, &image, NULL), RT_OK);
        assert_int_equal(image.sample_start, next);
        assert_true(image.samples_per_pixel == 2 || image.samples_per_pixel == 3);
        next += (uint32_t)image.samples_per_pixel;
    }
    assert_int_equal(next, 10);
    /* More shards than samples: a shard with none is an error, not an empty file. */
    scene_render_settings two_samples = scene_settings;
    two_samples.samples_per_pixel = 2;
    job.shard_index = 0;
    job.shard_count = 3;
    image_refused(&job, &two_samples, "shard 0/3 of 2 samples per pixel is empty; use fewer shards");
}

static void image_regions(void **state)
{
    (void)state;
    render_job_image image;
    render_job job = job_for("a.exr");
    assert_int_equal(plan_one(&job, &scene_settings, -1, &image, NULL), RT_OK);
    int none[4] = {0, 0, 0, 0}, whole[4] = {0, 0, 40, 30};
    assert_memory_equal(image.region, none, sizeof none);
    assert_memory_equal(image.window, whole, sizeof whole);
    /* A crop is the region and the window. */
    int crop[4] = {3, 4, 20, 9};
    memcpy(job.crop, crop, sizeof crop);
    assert_int_equal(plan_one(&job, &scene_settings, -1, &image, NULL), RT_OK);
    assert_memory_equal(image.region, crop, sizeof crop);
    assert_memory_equal(image.window, crop, sizeof crop);
    /* Tiles (and shards by tiles) are full-width bands that cover every row once. */
    for (int by_shard = 0; by_shard < 2; by_shard++) {
        job = job_for("a.exr");
        int next_row = 0;
        for (int i = 0; i < 4; i++) {
            if (by_shard) {
                job.shard_index = i;
                job.shard_count = 4;
                job.shard_by = RENDER_SHARD_TILES;
            } else {
                job.tile_index = i;
                job.tile_count = 4;
            }
            assert_int_equal(plan_one(&job, &scene_settings, -1, &image, NULL), RT_OK);
            assert_int_equal(image.region[0], 0);
            assert_int_equal(image.region[1], next_row);
            assert_int_equal(image.region[2], 40);
            assert_memory_equal(image.window, image.region, sizeof image.region);
            assert_int_equal(image.samples_per_pixel, 10);  /* a tile has every sample */
            next_row = image.region[3];
        }
        assert_int_equal(next_row, 30);
    }
    /* More tiles than rows: an empty one is an error. */
    scene_render_settings two_rows = scene_settings;
    two_rows.height = 2;
    job = job_for("a.exr");
    job.tile_count = 3;
    image_refused(&job, &two_rows, "tile 0/3 of a 2-row image is empty; use fewer tiles");
}

static void overrides_and_variables(void **state)
{
    (void)state;
    scene_render_settings settings = scene_settings;
    render_job job = job_for("a.exr");
    render_job_apply_overrides(&job, &settings);
    assert_int_equal(settings.width, 40);
    assert_int_equal(settings.seed, 1);
    job.samples_per_pixel = 3;
    job.width = 7;
    job.height = 2;
    job.max_depth = 9;
    job.seed_set = true;  /* seed 0 is a seed */
    render_job_apply_overrides(&job, &settings);
    scene_render_settings expected = {.width = 7, .height = 2, .samples_per_pixel = 3, .max_depth = 9, .seed = 0};
    assert_memory_equal(&settings, &expected, sizeof expected);

    scene_define given[] = {{.name = "a", .value = "1"}};
    job.defines = given;
    job.define_count = 1;
    scene_define defines[3];
    render_job_frame_values values;
    assert_int_equal(render_job_scene_defines(&job, -1, defines, &values), 1);
    assert_string_equal(defines[0].name, "a");
    /* A frame adds $frame and $time = frame / fps (24 by default), both optional. */
    assert_int_equal(render_job_scene_defines(&job, 6, defines, &values), 3);
    assert_string_equal(defines[1].name, "frame");
    assert_string_equal(defines[1].value, "6");
    assert_string_equal(defines[2].name, "time");
    assert_string_equal(defines[2].value, "0.25");
    assert_true(defines[1].optional && defines[2].optional && !defines[0].optional);
    job.frames_per_second = 3;
    render_job_scene_defines(&job, 1, defines, &values);
    assert_string_equal(defines[2].value, "0.33333333333333331");
}

/* A 2x3 part of a 5x4 image with R, G, B, samples, as a render returns it. */
static void make_part(rt_image *image)
{
    assert_int_equal(image_create(image, 2, 3, 4, NULL), RT_OK);
    static const char *const names[4] = {"R", "G", "B", "samples"};
    for (int c = 0; c < 4; c++)
        snprintf(image->channel_names[c], IMAGE_CHANNEL_NAME_MAX, "%s", names[c]);
    for (int i = 0; i < 6; i++) {
        image->pixels[4 * i + 0] = 0.1f * (float)i;
        image->pixels[4 * i + 1] = 0.5f;
        image->pixels[4 * i + 2] = 1.0f;
        image->pixels[4 * i + 3] = 4.0f;
    }
    image->x = 1;
    image->y = 1;
    image->full_width = 5;
    image->full_height = 4;
}

static void metadata_round_trip(void **state)
{
    (void)state;
    rt_image part, layers, read;
    make_part(&part);
    assert_int_equal(image_create(&layers, 2, 3, 1, NULL), RT_OK);
    snprintf(layers.channel_names[0], IMAGE_CHANNEL_NAME_MAX, "depth.Z");
    render_output_metadata metadata = {
        .scene = "scenes/x.txt", .scene_hash = "00000000deadbeef", .spp = 4, .sample_start = 3000000000ULL,
        .seed = 4294967295ULL, .max_depth = 8, .frame = 12, .samples_finished = 24, .path_segments = 1e10,
        .complete = true, .render_seconds = 1.5,
    };
    const char *path = job_path("part.exr");
    assert_int_equal(render_output_write(path, &part, &layers, &metadata, 0, NULL), RT_OK);
    /* The merge reads back what was written, and the layers follow the four channels. */
    merge_metadata back;
    assert_int_equal(merge_read_part(path, &read, &back, NULL), RT_OK);
    assert_merge_metadata_equal(&back, (&(merge_metadata){
                                           .scene = "scenes/x.txt", .scene_hash = "00000000deadbeef", .spp = 4,
                                           .sample_start = 3000000000ULL, .seed = 4294967295ULL, .max_depth = 8,
                                           .frame = 12, .complete = true, .render_seconds = 1.5,
                                           .path_segments = 1e10}));
    assert_int_equal(read.channels, 5);
    assert_string_equal(read.channel_names[4], "depth.Z");
    assert_int_equal(read.x, 1);
    assert_int_equal(read.full_width, 5);
    image_free(&read);
    char text[64];
    assert_int_equal(image_read_attribute(path, METADATA_KEY_SAMPLES_FINISHED, text, sizeof text, NULL), RT_OK);
    assert_string_equal(text, "24");
    /* merged_parts only in a merge. */
    assert_int_equal(image_read_attribute(path, METADATA_KEY_MERGED_PARTS, text, sizeof text, NULL), RT_ERROR_INPUT);
    metadata.merged_parts = 3;
    assert_int_equal(render_output_write(path, &part, NULL, &metadata, 0, NULL), RT_OK);
    assert_int_equal(image_read_attribute(path, METADATA_KEY_MERGED_PARTS, text, sizeof text, NULL), RT_OK);
    assert_string_equal(text, "3");
    /* Formats without a sample count get the colour only. */
    const char *png = job_path("part.png");
    assert_int_equal(render_output_write(png, &part, &layers, &metadata, 0, NULL), RT_OK);
    assert_int_equal(image_read(png, &read, NULL), RT_OK);
    assert_int_equal(read.channels, 3);
    image_free(&read);
    image_free(&layers);
    image_free(&part);
}

/* A file made from a render (rtspheres denoise, relight) says what the render said, less
 * the options hash (it is no longer what those options render), and what was done to it. */
static void derived_metadata(void **state)
{
    (void)state;
    rt_image part;
    make_part(&part);
    render_output_metadata metadata = {
        .scene = "scenes/x.txt", .scene_hash = "00000000deadbeef", .options_hash = "0123456789abcdef", .spp = 4,
        .seed = 4294967295ULL, .max_depth = 8, .frame = -1, .samples_finished = 24, .complete = true,
        .render_seconds = 1.5, .stop_reason = "spp",
    };
    const char *path = job_path("render.exr");
    assert_int_equal(render_output_write(path, &part, NULL, &metadata, 0, NULL), RT_OK);
    image_attribute_set derived = {0};
    rt_error error = {{0}};
    assert_int_equal(render_output_derived_metadata(path, "denoise", &derived, &error), RT_OK);
    assert_null(image_attribute_set_find(&derived, METADATA_KEY_OPTIONS_HASH));
    assert_string_equal(image_attribute_set_find(&derived, METADATA_KEY_POSTPROCESS)->string_value, "denoise");
    assert_string_equal(image_attribute_set_find(&derived, METADATA_KEY_SCENE_HASH)->string_value, "00000000deadbeef");
    assert_int_equal(image_attribute_set_find(&derived, METADATA_KEY_SPP)->int_value, 4);
    assert_string_equal(image_attribute_set_find(&derived, METADATA_KEY_SEED)->string_value, "4294967295");
    assert_string_equal(image_attribute_set_find(&derived, METADATA_KEY_STOP_REASON)->string_value, "spp");
    assert_true(image_attribute_set_find(&derived, METADATA_KEY_RENDER_SECONDS)->float_value == 1.5);

    /* Written and derived again, the steps add up in order. */
    image_write_options options = image_write_options_defaults();
    options.attributes = derived.attributes;
    options.attribute_count = derived.count;
    const char *denoised = job_path("denoised.exr");
    assert_int_equal(image_write(denoised, &part, &options, NULL), RT_OK);
    image_attribute_set_free(&derived);
    assert_int_equal(render_output_derived_metadata(denoised, "relight key=2", &derived, &error), RT_OK);
    assert_string_equal(image_attribute_set_find(&derived, METADATA_KEY_POSTPROCESS)->string_value,
                        "denoise; relight key=2");
    image_attribute_set_free(&derived);

    /* A file without rtspheres metadata: the step alone. A missing one: bad input. */
    const char *bare = job_path("bare.exr");
    assert_int_equal(image_write(bare, &part, NULL, NULL), RT_OK);
    assert_int_equal(render_output_derived_metadata(bare, "denoise", &derived, &error), RT_OK);
    assert_int_equal(derived.count, 1);
    assert_string_equal(derived.attributes[0].name, METADATA_KEY_POSTPROCESS);
    image_attribute_set_free(&derived);
    assert_int_equal(render_output_derived_metadata(job_path("absent.exr"), "denoise", &derived, &error),
                     RT_ERROR_INPUT);
    assert_contains(error.message, "absent.exr");
    assert_int_equal(derived.count, 0);

    /* The post-processed file is refused as a merge part, by the key. */
    rt_image read;
    merge_metadata back;
    assert_int_equal(merge_read_part(denoised, &read, &back, NULL), RT_OK);
    assert_string_equal(back.postprocess, "denoise");
    merger *m = NULL;
    assert_int_equal(merger_create(&m, &error), RT_OK);
    assert_int_equal(merger_add(m, denoised, &read, &back, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "post-processed");
    assert_contains(error.message, "rtspheres:postprocess \"denoise\"");
    merger_free(m);
    image_free(&read);
    image_free(&part);
}

static void partials(void **state)
{
    (void)state;
    rt_image part, read;
    make_part(&part);
    render_output_metadata metadata = {.scene = "s.txt", .scene_hash = "00000000000000ff", .spp = 4,
                                       .sample_start = 8, .seed = 7, .max_depth = 2, .frame = -1};
    const char *path = job_path("resume.partial.exr");
    assert_int_equal(render_output_write(path, &part, NULL, &metadata, 0, NULL), RT_OK);
    render_output_resume_check check = {.seed = 7, .sample_start = 8, .spp = 4, .region = {1, 1, 3, 4}};
    uint64_t hash = 0;
    assert_int_equal(render_output_read_partial(path, &check, &read, &hash, NULL), RT_OK);
    assert_true(hash == 0xff);
    assert_int_equal(read.width, 2);
    image_free(&read);
    /* Each thing that differs is named, file value first. */
    struct {
        render_output_resume_check check;
        const char *problem;
    } wrong[] = {
        {{.seed = 9, .sample_start = 8, .spp = 4, .region = {1, 1, 3, 4}}, "seed 7, this render 9"},
        {{.seed = 7, .sample_start = 0, .spp = 4, .region = {1, 1, 3, 4}}, "first sample 8, this render 0"},
        {{.seed = 7, .sample_start = 8, .spp = 5, .region = {1, 1, 3, 4}}, "4 spp, this render 5"},
        {{.seed = 7, .sample_start = 8, .spp = 4, .region = {0, 0, 5, 4}},
         "it covers another region of the image (size or crop differ)"},
    };
    for (size_t i = 0; i < sizeof wrong / sizeof wrong[0]; i++) {
        rt_error error = {{0}};
        char expected[1024];
        snprintf(expected, sizeof expected, "--resume %s does not belong to this render: %s", path, wrong[i].problem);
        assert_int_equal(render_output_read_partial(path, &wrong[i].check, &read, &hash, &error), RT_ERROR_INPUT);
        assert_string_equal(error.message, expected);
        assert_null(read.pixels);
    }
    rt_error error = {{0}};
    assert_int_equal(render_output_read_partial(job_path("none.exr"), &check, &read, &hash, &error), RT_ERROR_INPUT);
    assert_true(strncmp(error.message, "--resume: IMAGE: cannot read", 28) == 0);
    image_free(&part);
}

/* Counts what a job told its callbacks. */
typedef struct events {
    int started, finished, written, warnings;
    int frames[8];
    rt_status last_status;
} events;

static void count_started(void *user, const render_job_image *image)
{
    events *seen = user;
    if (seen->started < 8)
        seen->frames[seen->started] = image->frame;
    seen->started++;
}

static void count_finished(void *user, const render_job_image *image, rt_status status)
{
    (void)image;
    events *seen = user;
    seen->finished++;
    seen->last_status = status;
}

static void count_written(void *user, const render_job_image *image, const render_result *result)
{
    (void)image;
    (void)result;
    ((events *)user)->written++;
}

static render_job_callbacks callbacks_for(events *seen)
{
    memset(seen, 0, sizeof *seen);
    return (render_job_callbacks){.user = seen, .render_started = count_started, .render_finished = count_finished,
                                  .image_written = count_written};
}

/* Each of these jobs ends before it would need the GPU, so no context is given. */
static void runs_that_stop_early(void **state)
{
    (void)state;
    events seen;
    render_job_callbacks callbacks = callbacks_for(&seen);
    render_job_summary summary;
    rt_error error = {{0}};
    /* A refused plan. */
    render_job job = job_for("a.bmp");
    assert_int_equal(render_job_run(NULL, &job, &callbacks, &summary, &error), RT_ERROR_INPUT);
    assert_int_equal(summary.failure, RENDER_JOB_FAILURE_PLAN);
    assert_int_equal(summary.images_started, 0);
    /* A scene that does not parse: the parser's message, with the file's position. */
    const char *bad = write_file(work, "bad.txt", "sphere 0 0 0 1\n");
    job = job_for("a.exr");
    job.scene_path = bad;
    assert_int_equal(render_job_run(NULL, &job, &callbacks, &summary, &error), RT_ERROR_INPUT);
    assert_int_equal(summary.failure, RENDER_JOB_FAILURE_SCENE);
    assert_true(strncmp(error.message, bad, strlen(bad)) == 0);
    /* An empty shard of the samples, known once the scene says it has 4. */
    job = job_for("a.exr");
    job.shard_index = 0;
    job.shard_count = 5;
    assert_int_equal(render_job_run(NULL, &job, &callbacks, &summary, &error), RT_ERROR_INPUT);
    assert_int_equal(summary.failure, RENDER_JOB_FAILURE_IMAGE);
    assert_string_equal(error.message, "shard 0/5 of 4 samples per pixel is empty; use fewer shards");
    /* A partial of another render. */
    rt_image part;
    make_part(&part);
    render_output_metadata metadata = {.scene = "s.txt", .scene_hash = "1", .spp = 4, .seed = 99, .frame = -1};
    assert_int_equal(render_output_write(job_path("other.exr"), &part, NULL, &metadata, 0, NULL), RT_OK);
    image_free(&part);
    job = job_for("a.exr");
    job.resume_path = job_path("other.exr");
    assert_int_equal(render_job_run(NULL, &job, &callbacks, &summary, &error), RT_ERROR_INPUT);
    assert_int_equal(summary.failure, RENDER_JOB_FAILURE_IMAGE);
    assert_non_null(strstr(error.message, "does not belong to this render: seed 99, this render 3"));
    /* A stop request before the first frame: nothing is rendered or written. */
    int frames[] = {1, 2};
    volatile sig_atomic_t stop = 1;
    job = frames_job_for("f-%d.exr", frames, 2);
    job.stop_requested = &stop;
    assert_int_equal(render_job_run(NULL, &job, &callbacks, &summary, &error), RT_ERROR_INTERRUPTED);
    assert_int_equal(summary.failure, RENDER_JOB_FAILURE_STOPPED);
    assert_int_equal(summary.images_started, 0);
    assert_int_equal(seen.started, 0);
    assert_int_equal(access(job_path("f-1.exr"), F_OK), -1);
    /* A frame whose name is the scene file (the first name was checked by the plan). */
    const char *scene_exr = write_file(work, "scene-2.exr", scene_text);
    job = frames_job_for("scene-%d.exr", frames, 2);
    job.scene_path = scene_exr;
    job.shard_index = 1;
    job.shard_count = 2;
    char expected[1024];
    snprintf(expected, sizeof expected, "frame 2's output '%s' is the scene file; refusing to overwrite it",
             job_path("scene-2.exr"));
    assert_int_equal(render_job_run(NULL, &job, &callbacks, &summary, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, expected);
    assert_int_equal(summary.failure, RENDER_JOB_FAILURE_IMAGE);
}

/* A job of three frames sharded by frames, rendered on the device: only its frames are
 * written, each with its metadata, and no partial file stays. */
static void a_job_renders(void **state)
{
    (void)state;
    gpu_context *context = NULL;
    rt_error error = {{0}};
    if (gpu_create(NULL, &context, &error) != RT_OK)
        fail_msg("no device to render on: %s", error.message);
    events seen;
    render_job_callbacks callbacks = callbacks_for(&seen);
    int frames[] = {4, 5, 6};
    render_job job = frames_job_for("f-%d.exr", frames, 3);
    job.shard_index = 0;
    job.shard_count = 2;
    job.samples_per_pixel = 2;
    job.checkpoint_seconds = 1e6;
    render_job_summary summary;
    assert_int_equal(render_job_run(context, &job, &callbacks, &summary, &error), RT_OK);
    gpu_destroy(context);
    assert_int_equal(summary.failure, RENDER_JOB_FAILURE_NONE);
    assert_int_equal(summary.images_started, 2);
    assert_int_equal(seen.started, 2);
    assert_int_equal(seen.finished, 2);
    assert_int_equal(seen.written, 2);
    assert_int_equal(seen.frames[0], 4);
    assert_int_equal(seen.frames[1], 6);
    assert_int_equal(access(job_path("f-5.exr"), F_OK), -1);
    assert_int_equal(access(job_path("f-6.partial.exr"), F_OK), -1);
    rt_image image;
    merge_metadata metadata;
    assert_int_equal(merge_read_part(job_path("f-6.exr"), &image, &metadata, &error), RT_OK);
    assert_int_equal(image.width, 8);
    assert_int_equal(image.height, 6);
    assert_int_equal(metadata.frame, 6);
    assert_int_equal(metadata.spp, 2);
    assert_true(metadata.complete);
    assert_int_equal(metadata.max_depth, 3);
    for (int i = 0; i < 8 * 6; i++)
        assert_true(image.pixels[4 * i + 3] == 2.0f);
    image_free(&image);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(defaults_are_zero),
        cmocka_unit_test(output_names),
        cmocka_unit_test(output_rules),
        cmocka_unit_test(gltf_scene_rules),
        cmocka_unit_test(part_rules),
        cmocka_unit_test(shards),
        cmocka_unit_test(image_samples),
        cmocka_unit_test(image_regions),
        cmocka_unit_test(overrides_and_variables),
        cmocka_unit_test(options_hash),
        cmocka_unit_test(metadata_round_trip),
        cmocka_unit_test(derived_metadata),
        cmocka_unit_test(partials),
        cmocka_unit_test(runs_that_stop_early),
        cmocka_unit_test(a_job_renders),
    };
    return cmocka_run_group_tests(tests, make_job_scratch, remove_scratch);
}
