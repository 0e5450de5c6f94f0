// work.glsl: the work bound: how much a pixel may do in one pass.
//
// Why passes: llvmpipe silently ends all loops of one invocation after 65,535 iterations
// in total, and GPU drivers kill long draws. So a pixel does at most pass_work_budget
// units of work per pass, keeps an unfinished path in the state textures
// (glsl/main.glsl) and continues it in the next pass.
//
// llvmpipe runs the pixels of one SIMD vector (8 lanes at 256 bits) as one invocation:
// every loop runs until its slowest lane is done, and at least once even when no lane
// needs it. So work counts, per pixel, every loop iteration the pixel runs (every loop of
// the tracer adds to it) plus SEGMENT_WORK for each path segment, which is at least the
// number of loops a segment passes through. Then a vector's iterations are at most
// (lanes + 1) x the largest pixel's work, and the host picks work_cap (and the largest
// budget) so that stays under the cap (core/gpu.c set_work_limits). One traversal may run
// past the budget (it cannot be suspended) but not past work_cap: a pixel that would pass
// it stops and sets overflow, which is counted in the statistics and which the host turns
// into an error, never a silently wrong image. tests/render/test-pass-budget.sh checks
// that images do not depend on the budget.
const int SEGMENT_WORK = 64;
int work;            // this invocation's work so far
bool overflow;       // work_cap was reached: the path in flight is cut short

// Counts one loop iteration; false (and overflow set) when the cap is reached.
bool count_work()
{
    work++;
    if (work > work_cap)
        overflow = true;
    return !overflow;
}
