/* sampling_journal.h: the checkpoint of a sampling run, a journal of its
 * measured batches (sampling_journal.c). Not part of the public API. */
#ifndef RL_EVAL_SAMPLING_JOURNAL_H
#define RL_EVAL_SAMPLING_JOURNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "rl/rl_sampling.h"

typedef struct rl_journal rl_journal;

/* Opens path, made if missing, for a run described by key. An existing
 * file must have been made with the same key (else RL_ERR_IO naming it);
 * its batches are then replayed in order. */
rl_status rl_journal_open(const char *path, const char *key, rl_journal **out);
/* The next recorded batch: *hit true with its values (and sets, words per
 * position) copied when it has exactly these positions; *hit false when
 * the journal has no more whole batches (a cut-off one is cut away);
 * RL_ERR_INVALID_ARG when the recorded batch differs. */
rl_status rl_journal_replay(rl_journal *j, const rl_vec3 *pos, uint32_t n, double *values, uint64_t *sets,
                            size_t words, bool *hit);
/* Appends a measured batch and flushes it to the disk. */
rl_status rl_journal_append(rl_journal *j, const rl_vec3 *pos, uint32_t n, const double *values,
                            const uint64_t *sets, size_t words);
uint64_t rl_journal_replayed(const rl_journal *j);   /* positions answered from the file */
void rl_journal_close(rl_journal *j);                /* NULL is a no-op */

#endif
