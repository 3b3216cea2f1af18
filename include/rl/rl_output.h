/* rl_output.h: output files that are either complete or untouched.
 *
 * Every file renderlab writes (images, JSON, plots, Line Space caches)
 * goes through here. The bytes go to a temporary file in the target's
 * folder, ".NAME.XXXXXX.EXT" (the extension kept, so that a writer which
 * picks its format by the name still does), which is flushed to disk and
 * then renamed over the target. A write that fails partway (disk full, a
 * file size limit) leaves the old file as it was and removes the
 * temporary; a process killed mid-write leaves the old file and at worst a
 * hidden temporary, which nothing reads as the target. A new file gets
 * mode 0666 less the umask, a replaced one keeps its mode, and a symbolic
 * link is followed, so that the file it names is replaced. A target that
 * exists but is no regular file (/dev/null, a FIFO, a terminal) cannot be
 * renamed over and is written directly.
 *
 * A batch does the same for the outputs of one run together: it hands out
 * temporaries, and only when every one of them was written does the
 * caller commit the batch, which renames them all. A run whose last output
 * fails keeps the previous versions of all its outputs.
 *
 * Usage, a stream:
 *     rl_output *o;
 *     rl_status st = rl_output_open("stats.json", &o);
 *     if (st == RL_OK) {
 *         fputs(text, rl_output_file(o));
 *         st = rl_output_commit(o);          // or rl_output_abort(o)
 *     }
 * and writers that take a path (rl_image_write) in a batch:
 *     const char *tmp;
 *     st = rl_output_batch_add(batch, "out.png", &tmp);
 *     if (st == RL_OK) st = rl_image_write(img, tmp);
 *     ... the other outputs ...
 *     if (st == RL_OK) st = rl_output_batch_commit(batch);
 *     rl_output_batch_release(batch);        // removes what was not committed
 *
 * Failures: RL_ERR_IO with the target's name and the system's reason
 * (folder missing, not writable, disk full, the target is a folder);
 * RL_ERR_OUT_OF_MEMORY; RL_ERR_INVALID_ARG for NULL arguments. */
#ifndef RL_OUTPUT_H
#define RL_OUTPUT_H

#include <stdio.h>

#include "rl/rl_common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_output rl_output;                 /* opaque: one file being written */

/* Creates the temporary for path (or opens path itself when it is no
 * regular file). *out stays NULL on failure. */
RL_API rl_status rl_output_open(const char *path, rl_output **out);
/* The stream to write to; the commit finds any write error in it. */
RL_API FILE *rl_output_file(rl_output *o);
/* Where the bytes go: for a library that opens the file by name itself
 * (the stream then stays unused; the commit flushes whatever the file
 * holds by then). */
RL_API const char *rl_output_temp_path(const rl_output *o);
/* Flushes, syncs and closes the stream, then renames the temporary over
 * the target. Releases o whatever the result; on failure the temporary is
 * removed and the target is as it was. */
RL_API rl_status rl_output_commit(rl_output *o);
/* Closes the stream and removes the temporary; the target is untouched.
 * NULL is a no-op. */
RL_API void rl_output_abort(rl_output *o);

typedef struct rl_output_batch rl_output_batch;     /* opaque */

RL_API rl_status rl_output_batch_create(rl_output_batch **out);
/* Adds path: *write_to is an empty temporary in path's folder, with
 * path's extension, to be written by name (by a writer that replaces it,
 * as renderlab's writers do, or that truncates it); it stays valid until
 * the batch is released. A path that is no regular file is handed back as
 * it is and written at once. */
RL_API rl_status rl_output_batch_add(rl_output_batch *b, const char *path, const char **write_to);
/* Renames every temporary over its target, in the order they were added.
 * Should a rename fail (rare: the folder changed under the run), the
 * targets before it are already replaced and the rest are left as they
 * were; the error names the first that failed. */
RL_API rl_status rl_output_batch_commit(rl_output_batch *b);
/* Removes the temporaries not committed. NULL is a no-op. */
RL_API void rl_output_batch_release(rl_output_batch *b);

#ifdef __cplusplus
}
#endif
#endif
