/* load_fixtures.h: what the model-loading tests share: scratch folders,
 * files written byte for byte, base64 for glTF data URIs. Everything is
 * static inline, so a test uses any subset without unused-function
 * warnings. Failures are cmocka assertions (include <cmocka.h> first). */
#ifndef RL_TESTS_SCENE_LOAD_FIXTURES_H
#define RL_TESTS_SCENE_LOAD_FIXTURES_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* $RL_TEST_TMP/<group>/<sub>/ (created; the current folder without
 * RL_TEST_TMP) into out. */
static inline const char *fx_dir(const char *group, const char *sub, char *out, size_t size)
{
    const char *base = getenv("RL_TEST_TMP");
    char top[1024];
    snprintf(top, sizeof top, "%s/%s", base && base[0] ? base : ".", group);
    mkdir(top, 0777);
    size_t nt = strlen(top), ns = strlen(sub);
    assert_true(nt + 1 + ns < size);
    memcpy(out, top, nt);
    out[nt] = '/';
    memcpy(out + nt + 1, sub, ns + 1);
    mkdir(out, 0777);
    return out;
}

static inline void fx_write_bytes(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
}

/* Writes text into dir/name and returns the full path in out. */
static inline const char *fx_write_text(const char *dir, const char *name, const char *text,
                                        char *out, size_t size)
{
    snprintf(out, size, "%s/%s", dir, name);
    fx_write_bytes(out, text, strlen(text));
    return out;
}

/* RFC 4648 base64 of n bytes into out (4 * ceil(n / 3) + 1 bytes). */
static inline void fx_base64(const unsigned char *in, size_t n, char *out)
{
    static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16;
        if (i + 1 < n) v |= (uint32_t)in[i + 1] << 8;
        if (i + 2 < n) v |= in[i + 2];
        out[o++] = a[(v >> 18) & 63];
        out[o++] = a[(v >> 12) & 63];
        out[o++] = i + 1 < n ? a[(v >> 6) & 63] : '=';
        out[o++] = i + 2 < n ? a[v & 63] : '=';
    }
    out[o] = '\0';
}

#endif
