/* sampling_journal.c: the checkpoint of a sampling run
 * (rl_sampling_desc.checkpoint), so that a long evaluation that stops (a
 * killed job, a lost node, a machine lent for a few hours) is continued by
 * the same command instead of being started over.
 *
 * The sampler chooses its positions from its seed and the values it has
 * measured (Jähn 2015, Alg. 5.3), never from the clock. A journal of every
 * measured batch is therefore enough: a restarted run replays the recorded
 * batches in order, which leads it to the same next positions, and measures
 * from where the journal ends. Each replayed batch must have exactly the
 * recorded positions; any difference means the file belongs to another run
 * and is an error, never overwritten.
 *
 * File: the header "RLSJ" + version + key length + key (the property, its
 * options, the set size, the sampling parameters and the caller's own key,
 * e.g. the scene), then one record per batch: "BTCH", count, words, count
 * positions (3 floats), count values (doubles), count * words set words,
 * and an FNV-1a hash of the record. Records are appended and flushed to
 * the disk one by one; a record cut off by a killed process (short, or
 * its hash wrong) ends the journal there and is cut away. Native byte
 * order: a checkpoint continues a run on the same kind of machine. */
#define _POSIX_C_SOURCE 200809L
#include "eval/sampling_journal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"

#define JOURNAL_MAGIC "RLSJ"
#define JOURNAL_VERSION 1u
#define RECORD_MAGIC "BTCH"
#define MAX_KEY (64u * 1024u)

struct rl_journal {
    FILE *f;
    char *path;
    uint64_t batches;              /* records read or written so far */
    uint64_t replayed;             /* positions answered from the file */
    bool replaying;                /* records may follow the read position */
    off_t end_good;                /* the end of the last whole record */
    off_t size;                    /* the file's size when opened */
};

static uint64_t fnv1a(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

#define FNV_START 14695981039346656037ull

static rl_status io_error(const rl_journal *j, const char *what)
{
    return rl_error(RL_ERR_IO, "checkpoint %s: %s", j->path, what);
}

rl_status rl_journal_open(const char *path, const char *key, rl_journal **out)
{
    *out = NULL;
    size_t key_len = strlen(key);
    if (key_len > MAX_KEY)
        return rl_error(RL_ERR_LIMIT, "checkpoint %s: a key of %zu bytes (at most %u)", path, key_len, MAX_KEY);
    struct stat sb;
    bool exists = stat(path, &sb) == 0;
    if (exists && !S_ISREG(sb.st_mode))
        return rl_error(RL_ERR_IO, "checkpoint %s: not a regular file", path);
    rl_journal *j = calloc(1, sizeof *j);
    char *p = strdup(path);
    if (!j || !p) {
        free(j);
        free(p);
        return RL_ERR_OUT_OF_MEMORY;
    }
    j->path = p;
    j->f = fopen(path, exists ? "r+b" : "w+b");
    if (!j->f) {
        rl_status st = rl_error(RL_ERR_IO, "checkpoint %s: cannot open it for writing", path);
        rl_journal_close(j);
        return st;
    }
    uint32_t version = JOURNAL_VERSION, len = (uint32_t)key_len;
    if (!exists || sb.st_size == 0) {
        if (fwrite(JOURNAL_MAGIC, 4, 1, j->f) != 1 || fwrite(&version, sizeof version, 1, j->f) != 1 ||
            fwrite(&len, sizeof len, 1, j->f) != 1 || (key_len && fwrite(key, key_len, 1, j->f) != 1) ||
            fflush(j->f) != 0 || fsync(fileno(j->f)) != 0) {
            rl_status st = io_error(j, "cannot write its header");
            rl_journal_close(j);
            return st;
        }
        j->end_good = (off_t)(12 + key_len);
        *out = j;
        return RL_OK;
    }
    j->size = sb.st_size;
    char magic[4];
    uint32_t v = 0, l = 0;
    if (fread(magic, 4, 1, j->f) != 1 || memcmp(magic, JOURNAL_MAGIC, 4) != 0 || fread(&v, sizeof v, 1, j->f) != 1 ||
        v != JOURNAL_VERSION || fread(&l, sizeof l, 1, j->f) != 1) {
        rl_status st = io_error(j, "not a renderlab sampling checkpoint (or of another version); delete it or "
                                   "choose another file");
        rl_journal_close(j);
        return st;
    }
    rl_status st = RL_OK;
    if (l != len || (off_t)(12 + (uint64_t)l) > sb.st_size) {
        st = io_error(j, "it belongs to another evaluation (property, options, scene or sampling settings "
                         "differ); delete it or choose another file");
    } else if (len) {
        char *stored = malloc(len);
        if (!stored)
            st = RL_ERR_OUT_OF_MEMORY;
        else if (fread(stored, len, 1, j->f) != 1)
            st = io_error(j, "cannot read its header");
        else if (memcmp(stored, key, len) != 0)
            st = io_error(j, "it belongs to another evaluation (property, options, scene or sampling settings "
                             "differ); delete it or choose another file");
        free(stored);
    }
    if (st != RL_OK) {
        rl_journal_close(j);
        return st;
    }
    j->end_good = (off_t)(12 + key_len);
    j->replaying = true;
    *out = j;
    return RL_OK;
}

/* Cuts the file after the last whole record and ends the replay: from
 * here on, batches are measured and appended. */
static rl_status end_replay(rl_journal *j)
{
    j->replaying = false;
    if (fflush(j->f) != 0 || ftruncate(fileno(j->f), j->end_good) != 0 || fseeko(j->f, j->end_good, SEEK_SET) != 0)
        return io_error(j, "cannot cut off its unfinished end");
    return RL_OK;
}

rl_status rl_journal_replay(rl_journal *j, const rl_vec3 *pos, uint32_t n, double *values, uint64_t *sets,
                            size_t words, bool *hit)
{
    *hit = false;
    if (!j->replaying)
        return RL_OK;
    const off_t left = j->size - j->end_good;
    char magic[4];
    uint32_t count = 0;
    uint64_t w = 0;
    const size_t head = 4 + sizeof count + sizeof w;
    if (left < (off_t)head || fread(magic, 4, 1, j->f) != 1 || fread(&count, sizeof count, 1, j->f) != 1 ||
        fread(&w, sizeof w, 1, j->f) != 1 || memcmp(magic, RECORD_MAGIC, 4) != 0)
        return end_replay(j);                    /* the journal's end, or a record cut off in its header */
    /* Sizes checked against the file before anything is read or made. */
    const uint64_t body = (uint64_t)count * (sizeof(rl_vec3) + sizeof(double) + w * sizeof(uint64_t));
    if (count == 0 || count > RL_SAMPLING_MAX_SAMPLES || w > (uint64_t)1 << 26 ||
        (uint64_t)left < head + body + sizeof(uint64_t))
        return end_replay(j);
    if (count != n || w != (uint64_t)(sets ? words : 0))
        return rl_error(RL_ERR_INVALID_ARG, "checkpoint %s: batch %llu has %u positions, this run %u: it belongs "
                        "to another evaluation; delete it or choose another file", j->path,
                        (unsigned long long)j->batches + 1, count, n);
    rl_vec3 *rp = malloc((size_t)count * sizeof *rp);
    double *rv = malloc((size_t)count * sizeof *rv);
    uint64_t *rs = w ? malloc((size_t)(count * w) * sizeof *rs) : NULL;
    rl_status st = RL_OK;
    uint64_t sum = 0, h = FNV_START;
    if (!rp || !rv || (w && !rs)) {
        st = RL_ERR_OUT_OF_MEMORY;
    } else if (fread(rp, sizeof *rp, count, j->f) != count || fread(rv, sizeof *rv, count, j->f) != count ||
               (w && fread(rs, sizeof *rs, (size_t)(count * w), j->f) != (size_t)(count * w)) ||
               fread(&sum, sizeof sum, 1, j->f) != 1) {
        st = end_replay(j);
    } else {
        h = fnv1a(h, &count, sizeof count);
        h = fnv1a(h, &w, sizeof w);
        h = fnv1a(h, rp, (size_t)count * sizeof *rp);
        h = fnv1a(h, rv, (size_t)count * sizeof *rv);
        if (w)
            h = fnv1a(h, rs, (size_t)(count * w) * sizeof *rs);
        if (h != sum) {
            st = end_replay(j);          /* cut off while being written */
        } else if (memcmp(rp, pos, (size_t)count * sizeof *rp) != 0) {
            st = rl_error(RL_ERR_INVALID_ARG, "checkpoint %s: batch %llu was measured at other positions: it "
                          "belongs to another evaluation (a different seed, region or sample budget); delete it "
                          "or choose another file", j->path, (unsigned long long)j->batches + 1);
        } else {
            memcpy(values, rv, (size_t)count * sizeof *rv);
            if (w)
                memcpy(sets, rs, (size_t)(count * w) * sizeof *rs);
            j->end_good += (off_t)(head + body + sizeof sum);
            ++j->batches;
            j->replayed += count;
            *hit = true;
        }
    }
    free(rp);
    free(rv);
    free(rs);
    return st;
}

rl_status rl_journal_append(rl_journal *j, const rl_vec3 *pos, uint32_t n, const double *values,
                            const uint64_t *sets, size_t words)
{
    if (j->replaying) {
        rl_status st = end_replay(j);
        if (st != RL_OK)
            return st;
    }
    uint64_t w = sets ? words : 0, h = FNV_START;
    h = fnv1a(h, &n, sizeof n);
    h = fnv1a(h, &w, sizeof w);
    h = fnv1a(h, pos, (size_t)n * sizeof *pos);
    h = fnv1a(h, values, (size_t)n * sizeof *values);
    if (w)
        h = fnv1a(h, sets, (size_t)(n * w) * sizeof *sets);
    if (fwrite(RECORD_MAGIC, 4, 1, j->f) != 1 || fwrite(&n, sizeof n, 1, j->f) != 1 ||
        fwrite(&w, sizeof w, 1, j->f) != 1 || fwrite(pos, sizeof *pos, n, j->f) != n ||
        fwrite(values, sizeof *values, n, j->f) != n ||
        (w && fwrite(sets, sizeof *sets, (size_t)(n * w), j->f) != (size_t)(n * w)) ||
        fwrite(&h, sizeof h, 1, j->f) != 1 || fflush(j->f) != 0 || fdatasync(fileno(j->f)) != 0)
        return io_error(j, "cannot append a batch (disk full?); the batches before it are kept");
    j->end_good += (off_t)(4 + sizeof n + sizeof w + (size_t)n * (sizeof *pos + sizeof *values) +
                           (size_t)(n * w) * sizeof *sets + sizeof h);
    ++j->batches;
    return RL_OK;
}

uint64_t rl_journal_replayed(const rl_journal *j) { return j ? j->replayed : 0; }

void rl_journal_close(rl_journal *j)
{
    if (!j)
        return;
    if (j->f)
        fclose(j->f);
    free(j->path);
    free(j);
}
