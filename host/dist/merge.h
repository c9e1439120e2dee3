/*
 * merge.h — `clpt merge -o OUT PART...`: the films of independent partial renders
 * (--sample-range A:B --checkpoint PART) added into one.
 *
 * Every part is a checkpoint (docs/checkpoint.md) of the same render (its key: scene,
 * settings, kernels) holding the sample indices it rendered. The film is integer, so
 * adding the parts' sums gives exactly the sums one process would have accumulated:
 * the merged image is the same bits as the one-process render, whatever the split.
 * Parts may come from renders of different samples per pixel (a render grown after it
 * finished): the merged render has the largest count, and the parts must hold all of it.
 * Parts of other renders, parts that hold a sample twice and sets of parts that leave a
 * sample out are refused (ST_INPUT), naming the parts and samples concerned.
 * `merge --denoise` of parts rendered with --denoise adds their denoiser features the
 * same way and denoises as one process would: the same bits as its --denoise image.
 */
#ifndef CLPT_MERGE_H
#define CLPT_MERGE_H

#include "base/status.h"
#include "render/checkpoint.h"

/* Reads the parts and adds them into *out (its id is theirs with the largest spp, its
 * done ranges the union, which must be all of [0, spp)). With `features` (merge
 * --denoise) the parts' denoiser features (rendered with --denoise: checkpoint.h) are
 * added too, and every part must hold them, for the merged count, or none may; without,
 * they are dropped. Free *out with checkpoint_free, also after a failure. */
Status merge_parts(const char *const *paths, size_t n, int features, Checkpoint *out, Error *err);

/* The command: argv[0] is "merge". Returns the exit status; err holds the message. */
Status merge_command(int argc, char **argv, Error *err);

#endif /* CLPT_MERGE_H */
