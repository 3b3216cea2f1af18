/* test_image.c: image allocation limits, PNG/EXR round trips, extension
 * dispatch, I/O errors, texture loading and bilinear/repeat sampling. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <png.h>

#include "rl/rl_image.h"

static char *tmp_path(const char *name)
{
    static char buf[4][1024];
    static int next;
    const char *dir = getenv("RL_TEST_TMP");
    char *p = buf[next++ % 4];
    snprintf(p, sizeof buf[0], "%s/test_image_%s", dir && *dir ? dir : "/tmp", name);
    return p;
}

static bool file_exists(const char *path) { return access(path, F_OK) == 0; }

static void test_create_clears_every_layer(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(3, 2, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &img), RL_OK);
    assert_int_equal(img->width, 3);
    for (int i = 0; i < 6; ++i) {
        assert_true(img->color[i].x == 0 && img->color[i].w == 0);
        assert_true(isinf(img->depth[i]) && img->depth[i] > 0);
        assert_int_equal(img->object_id[i], RL_ID_NONE);
        assert_int_equal(img->triangle_id[i], RL_ID_NONE);
    }
    rl_image_fill(img, rl_v4(1, 2, 3, 4));
    assert_true(rl_image_pixel(img, 2, 1)->z == 3);
    img->depth[4] = 1.0f;
    img->object_id[4] = img->triangle_id[5] = 7;
    rl_image_clear_to(img, rl_v4(0.5f, 0.25f, 0.125f, 1.0f));
    for (int i = 0; i < 6; ++i) {
        assert_true(img->color[i].x == 0.5f && img->color[i].y == 0.25f &&
                    img->color[i].z == 0.125f && img->color[i].w == 1.0f);
        assert_true(isinf(img->depth[i]) && img->depth[i] > 0);
        assert_int_equal(img->object_id[i], RL_ID_NONE);
        assert_int_equal(img->triangle_id[i], RL_ID_NONE);
    }
    rl_image_release(img);
    rl_image_release(NULL);
}

static void test_absurd_sizes_are_refused_with_limit(void **state)
{
    (void)state;
    rl_image *img = NULL;
    rl_clear_error();
    assert_int_equal(rl_image_create(0, 0, RL_LAYER_COLOR, &img), RL_ERR_LIMIT);
    assert_null(img);
    rl_clear_error();
    assert_int_equal(rl_image_create(16385, 1, RL_LAYER_COLOR, &img), RL_ERR_LIMIT);
    assert_non_null(strstr(rl_last_error(), "16385"));
    assert_null(img);
    assert_int_equal(rl_image_create(-4, 10, RL_LAYER_COLOR, &img), RL_ERR_LIMIT);
    rl_texture *tex = NULL;
    rl_vec4 texel = { 0, 0, 0, 0 };
    assert_int_equal(rl_texture_create(16385, 1, &texel, &tex), RL_ERR_LIMIT);
    assert_null(tex);
    rl_clear_error();
}

static void test_png_round_trip_is_exact_for_8bit_values(void **state)
{
    (void)state;
    rl_image *img = NULL, *back = NULL;
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &img), RL_OK);
    for (int k = 0; k < 256; ++k) {
        float v = rl_srgb_to_linear((float)k / 255.0f);
        float v2 = rl_srgb_to_linear((float)(255 - k) / 255.0f);
        img->color[k] = rl_v4(v, v2, v, (float)((k * 7) % 256) / 255.0f);
    }
    const char *path = tmp_path("roundtrip.PNG"); /* extension case must not matter */
    assert_int_equal(rl_image_write(img, path), RL_OK);
    assert_int_equal(rl_image_read(path, &back), RL_OK);
    assert_int_equal(back->width, 16);
    assert_int_equal(back->height, 16);
    assert_int_equal(back->layers, RL_LAYER_COLOR);
    for (int k = 0; k < 256; ++k) {
        assert_true(back->color[k].x == img->color[k].x);
        assert_true(back->color[k].y == img->color[k].y);
        assert_true(back->color[k].w == img->color[k].w);
    }
    rl_image_release(back);
    rl_image_release(img);
}

static void test_png_clamps_out_of_range_and_nan(void **state)
{
    (void)state;
    rl_image *img = NULL, *back = NULL;
    assert_int_equal(rl_image_create(4, 1, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = rl_v4(2.0f, -1.0f, NAN, 1.0f);
    img->color[1] = rl_v4(INFINITY, -INFINITY, 0.5f, 3.0f);
    const char *path = tmp_path("clamp.png");
    assert_int_equal(rl_image_write_png(img, path), RL_OK);
    assert_int_equal(rl_image_read(path, &back), RL_OK);
    assert_true(back->color[0].x == 1.0f && back->color[0].y == 0.0f && back->color[0].z == 0.0f);
    assert_true(back->color[1].x == 1.0f && back->color[1].y == 0.0f && back->color[1].w == 1.0f);
    assert_true(fabsf(back->color[1].z - 0.5f) < 0.005f);
    rl_image_release(back);
    rl_image_release(img);
}

static void test_exr_round_trip_keeps_half_precision(void **state)
{
    (void)state;
    rl_image *img = NULL, *back = NULL;
    assert_int_equal(rl_image_create(7, 5, RL_LAYER_COLOR | RL_LAYER_DEPTH, &img), RL_OK);
    for (int i = 0; i < 35; ++i)
        img->color[i] = rl_v4(0.001f * (float)i, 3.7f * (float)i, 1000.0f / (float)(i + 1), 0.5f);
    const char *path = tmp_path("roundtrip.exr");
    assert_int_equal(rl_image_write(img, path), RL_OK);
    assert_int_equal(rl_image_read(path, &back), RL_OK);
    assert_int_equal(back->width, 7);
    assert_int_equal(back->height, 5);
    for (int i = 0; i < 35; ++i) {
        const float *a = &img->color[i].x, *b = &back->color[i].x;
        for (int c = 0; c < 4; ++c)
            assert_true(fabsf(a[c] - b[c]) <= 1e-3f * fabsf(a[c]) + 1e-7f);
    }
    rl_image_release(back);
    rl_image_release(img);
}

static void test_unknown_extension_is_unsupported_and_writes_nothing(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 2, RL_LAYER_COLOR, &img), RL_OK);
    const char *path = tmp_path("picture.bmp");
    unlink(path);
    rl_clear_error();
    assert_int_equal(rl_image_write(img, path), RL_ERR_UNSUPPORTED);
    assert_non_null(strstr(rl_last_error(), ".bmp"));
    assert_non_null(strstr(rl_last_error(), ".png"));
    assert_false(file_exists(path));
    rl_clear_error();
    assert_int_equal(rl_image_write(img, tmp_path("noext")), RL_ERR_UNSUPPORTED);
    /* A colour-less image is an argument error before the file is touched. */
    rl_image *depth_only = NULL;
    assert_int_equal(rl_image_create(2, 2, RL_LAYER_DEPTH, &depth_only), RL_OK);
    const char *png = tmp_path("depth_only.png");
    unlink(png);
    assert_int_equal(rl_image_write(depth_only, png), RL_ERR_INVALID_ARG);
    assert_false(file_exists(png));
    rl_image_release(depth_only);
    rl_image_release(img);
    rl_clear_error();
}

static void test_unwritable_path_is_an_io_error(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 2, RL_LAYER_COLOR, &img), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_image_write(img, "/nonexistent-dir/x.png"), RL_ERR_IO);
    assert_non_null(strstr(rl_last_error(), "/nonexistent-dir/x.png: cannot open for writing: "));
    rl_clear_error();
    assert_int_equal(rl_image_write(img, "/nonexistent-dir/x.exr"), RL_ERR_IO);
    assert_non_null(strstr(rl_last_error(), "cannot open for writing"));
    rl_image *back = NULL;
    assert_int_equal(rl_image_read("/nonexistent-dir/x.png", &back), RL_ERR_IO);
    assert_int_equal(rl_image_read("/nonexistent-dir/x.exr", &back), RL_ERR_IO);
    assert_null(back);
    rl_image_release(img);
    rl_clear_error();
}

/* 2x2 picture: top row red, green; bottom row blue, white (all 8-bit exact). */
static rl_image *quad_image(void)
{
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 2, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = rl_v4(1, 0, 0, 1);
    img->color[1] = rl_v4(0, 1, 0, 1);
    img->color[2] = rl_v4(0, 0, 1, 1);
    img->color[3] = rl_v4(1, 1, 1, 1);
    return img;
}

static void assert_vec4_near(rl_vec4 a, rl_vec4 b, float eps)
{
    if (!(fabsf(a.x - b.x) <= eps && fabsf(a.y - b.y) <= eps && fabsf(a.z - b.z) <= eps &&
          fabsf(a.w - b.w) <= eps))
        fail_msg("(%g %g %g %g) != (%g %g %g %g)", a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w);
}

static void test_texture_loads_png_with_uv_origin_bottom_left(void **state)
{
    (void)state;
    rl_image *img = quad_image();
    const char *path = tmp_path("texture.png");
    assert_int_equal(rl_image_write(img, path), RL_OK);
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_load(path, &tex), RL_OK);
    assert_int_equal(tex->width, 2);
    assert_int_equal(tex->height, 2);
    assert_string_equal(tex->path, path);
    for (int i = 0; i < 4; ++i)  /* row 0 is the top of the picture */
        assert_vec4_near(tex->texels[i], img->color[i], 0);
    /* Texel centres: uv (0.25, 0.25) is the bottom-left texel (blue). */
    assert_vec4_near(rl_texture_sample(tex, rl_v2(0.25f, 0.25f)), rl_v4(0, 0, 1, 1), 1e-6f);
    assert_vec4_near(rl_texture_sample(tex, rl_v2(0.25f, 0.75f)), rl_v4(1, 0, 0, 1), 1e-6f);
    assert_vec4_near(rl_texture_sample(tex, rl_v2(0.75f, 0.75f)), rl_v4(0, 1, 0, 1), 1e-6f);
    assert_vec4_near(rl_texture_sample(tex, rl_v2(0.75f, 0.25f)), rl_v4(1, 1, 1, 1), 1e-6f);
    rl_texture_release(tex);
    rl_image_release(img);
}

static void test_texture_sampling_is_bilinear_with_repeat(void **state)
{
    (void)state;
    /* 2x1 texture: left 0, right 1 (only red used). */
    rl_vec4 texels[2] = { { 0, 0, 0, 1 }, { 1, 0, 0, 1 } };
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(2, 1, texels, &tex), RL_OK);
    texels[0].x = 5; /* copied, so this must not show */
    assert_null(tex->path);
    assert_true(fabsf(rl_texture_sample(tex, rl_v2(0.25f, 0.5f)).x - 0.0f) < 1e-6f);
    assert_true(fabsf(rl_texture_sample(tex, rl_v2(0.5f, 0.5f)).x - 0.5f) < 1e-6f);
    assert_true(fabsf(rl_texture_sample(tex, rl_v2(0.375f, 0.5f)).x - 0.25f) < 1e-6f);
    /* Halfway between the right texel and the wrapped-around left one. */
    assert_true(fabsf(rl_texture_sample(tex, rl_v2(1.0f, 0.5f)).x - 0.5f) < 1e-6f);
    assert_true(fabsf(rl_texture_sample(tex, rl_v2(0.875f, 0.5f)).x - 0.75f) < 1e-6f);
    /* Repeat: whole-number shifts in u and v change nothing. */
    for (float u = 0.05f; u < 1.0f; u += 0.1f) {
        float ref = rl_texture_sample(tex, rl_v2(u, 0.3f)).x;
        assert_true(fabsf(rl_texture_sample(tex, rl_v2(u + 3.0f, 0.3f)).x - ref) < 1e-5f);
        assert_true(fabsf(rl_texture_sample(tex, rl_v2(u - 2.0f, -4.7f)).x - ref) < 1e-5f);
    }
    /* Non-finite coordinates do not crash and stay in range. */
    float nanx = rl_texture_sample(tex, rl_v2(NAN, INFINITY)).x;
    assert_true(nanx >= 0 && nanx <= 1);
    rl_texture_release(tex);
    rl_texture_release(NULL);
}

static void write_bytes(const char *path, const unsigned char *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static void test_corrupted_png_is_an_error_not_a_crash(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(32, 32, RL_LAYER_COLOR, &img), RL_OK);
    for (int i = 0; i < 32 * 32; ++i)
        img->color[i] = rl_v4((float)(i % 17) / 17.0f, (float)(i % 5) / 5.0f, 0.3f, 1);
    const char *good = tmp_path("good.png");
    assert_int_equal(rl_image_write(img, good), RL_OK);
    rl_image_release(img);
    FILE *f = fopen(good, "rb");
    assert_non_null(f);
    unsigned char data[65536];
    size_t n = fread(data, 1, sizeof data, f);
    fclose(f);
    assert_true(n > 100 && n < sizeof data);

    const char *bad = tmp_path("bad.png");
    /* Truncated in the middle of the image data. */
    write_bytes(bad, data, n / 2);
    rl_image *back = NULL;
    rl_texture *tex = NULL;
    assert_int_equal(rl_image_read(bad, &back), RL_ERR_PARSE);
    assert_null(back);
    assert_int_equal(rl_texture_load(bad, &tex), RL_ERR_PARSE);
    assert_null(tex);
    /* Bytes flipped after the header: CRC or zlib errors. */
    for (size_t i = 40; i < n; i += 7)
        data[i] ^= 0x5a;
    write_bytes(bad, data, n);
    assert_int_equal(rl_image_read(bad, &back), RL_ERR_PARSE);
    assert_null(back);
    /* Not an image at all. */
    write_bytes(bad, (const unsigned char *)"hello", 5);
    assert_int_equal(rl_image_read(bad, &back), RL_ERR_PARSE);
    assert_int_equal(rl_texture_load(bad, &tex), RL_ERR_PARSE);
    assert_int_equal(rl_texture_load(tmp_path("missing.png"), &tex), RL_ERR_IO);
    assert_null(tex);
    write_bytes(tmp_path("bad.exr"), (const unsigned char *)"not an exr file", 15);
    assert_int_equal(rl_image_read(tmp_path("bad.exr"), &back), RL_ERR_PARSE);
    assert_null(back);
    rl_clear_error();
}

/* Writes a PNG with libpng directly, in layouts our writer never produces. */
static void write_raw_png(const char *path, int w, int h, int depth, int color_type,
                          const unsigned char *rows_data, size_t rowbytes)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png_create_info_struct(png);
    assert_non_null(info);
    if (setjmp(png_jmpbuf(png)))
        fail_msg("libpng failed writing the test file");
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, depth, color_type, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < h; ++y)
        png_write_row(png, rows_data + (size_t)y * rowbytes);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    fclose(f);
}

static void test_png_reader_expands_16bit_and_grey_to_rgba(void **state)
{
    (void)state;
    /* 16-bit RGB, big-endian samples: 0, 65535 and 32768 (mid sRGB grey). */
    const unsigned char rgb16[] = { 0x00, 0x00, 0xFF, 0xFF, 0x80, 0x00,
                                    0xFF, 0xFF, 0x00, 0x00, 0x00, 0x00 };
    const char *path = tmp_path("rgb16.png");
    write_raw_png(path, 2, 1, 16, PNG_COLOR_TYPE_RGB, rgb16, sizeof rgb16);
    rl_image *img = NULL;
    assert_int_equal(rl_image_read(path, &img), RL_OK);
    assert_int_equal(img->width, 2);
    assert_true(img->color[0].x == 0.0f && img->color[0].y == 1.0f && img->color[0].w == 1.0f);
    assert_true(fabsf(img->color[0].z - rl_srgb_to_linear(32768.0f / 65535.0f)) < 1e-6f);
    assert_true(img->color[1].x == 1.0f && img->color[1].z == 0.0f && img->color[1].w == 1.0f);
    rl_image_release(img);
    /* 8-bit grey: replicated into r, g, b with opaque alpha. */
    const unsigned char grey[] = { 0, 128, 255 };
    path = tmp_path("grey8.png");
    write_raw_png(path, 1, 3, 8, PNG_COLOR_TYPE_GRAY, grey, 1);
    assert_int_equal(rl_image_read(path, &img), RL_OK);
    assert_int_equal(img->height, 3);
    float mid = rl_srgb_to_linear(128.0f / 255.0f);
    assert_true(img->color[1].x == mid && img->color[1].y == mid && img->color[1].z == mid);
    assert_true(img->color[2].x == 1.0f && img->color[0].w == 1.0f);
    rl_image_release(img);
    /* The same file as a texture, through stb_image. */
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_load(path, &tex), RL_OK);
    assert_true(fabsf(tex->texels[1].y - mid) < 1e-6f && tex->texels[1].w == 1.0f);
    rl_texture_release(tex);
}

static unsigned char *read_all(const char *path, size_t *n)
{
    static unsigned char data[65536];
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    *n = fread(data, 1, sizeof data, f);
    fclose(f);
    assert_true(*n > 0 && *n < sizeof data);
    return data;
}

/* An EXR header attribute that claims a gigabyte: refused before OpenEXR
 * allocates it (issue 34; fuzz_texture found such files). */
static void test_exr_attribute_longer_than_the_file_is_refused(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(4, 4, RL_LAYER_COLOR, &img), RL_OK);
    const char *good = tmp_path("small.exr");
    assert_int_equal(rl_image_write(img, good), RL_OK);
    rl_image_release(img);
    size_t n = 0;
    unsigned char *data = read_all(good, &n);
    unsigned char *at = NULL;
    for (size_t i = 0; i + 24 < n && !at; ++i)
        if (memcmp(data + i, "compression\0compression\0", 24) == 0)
            at = data + i + 24;
    assert_non_null(at);
    int32_t size = 0x40000000;
    memcpy(at, &size, 4);
    const char *bad = tmp_path("huge_attribute.exr");
    write_bytes(bad, data, n);
    rl_image *back = NULL;
    rl_clear_error();
    assert_int_equal(rl_image_read(bad, &back), RL_ERR_PARSE);
    assert_null(back);
    if (!strstr(rl_last_error(), "longer than the file"))
        fail_msg("not refused by the attribute check: %s", rl_last_error());
    rl_clear_error();
}

/* An EXR whose one chunk declares 1.9 GB: refused before OpenEXR
 * allocates it (fuzz_texture found such files). */
static void test_exr_chunk_longer_than_the_file_is_refused(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(4, 4, RL_LAYER_COLOR, &img), RL_OK);
    const char *good = tmp_path("small.exr");
    assert_int_equal(rl_image_write(img, good), RL_OK);
    rl_image_release(img);
    size_t n = 0;
    unsigned char *data = read_all(good, &n);
    /* The chunk: y = 0, then its size, which runs to the end of the file. */
    unsigned char *at = NULL;
    for (size_t i = 4; i + 4 <= n && !at; ++i) {
        int32_t y, size;
        memcpy(&y, data + i - 4, 4);
        memcpy(&size, data + i, 4);
        if (y == 0 && size > 0 && (size_t)size == n - i - 4)
            at = data + i;
    }
    assert_non_null(at);
    int32_t huge = 1932551434;
    memcpy(at, &huge, 4);
    const char *bad = tmp_path("huge_chunk.exr");
    write_bytes(bad, data, n);
    rl_image *back = NULL;
    rl_clear_error();
    assert_int_equal(rl_image_read(bad, &back), RL_ERR_PARSE);
    assert_null(back);
    if (!strstr(rl_last_error(), "longer than the file"))
        fail_msg("not refused by the chunk check: %s", rl_last_error());
    rl_clear_error();
}

/* A PNG whose IDAT chunk declares 2 GB: the texture loader refuses it
 * before stb_image grows a buffer to that length (fuzz_texture found it:
 * 8 s and gigabytes for 231 bytes). */
static void test_png_chunk_longer_than_the_file_is_refused_by_the_texture_loader(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(4, 4, RL_LAYER_COLOR, &img), RL_OK);
    const char *good = tmp_path("chunk.png");
    assert_int_equal(rl_image_write(img, good), RL_OK);
    rl_image_release(img);
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_load(good, &tex), RL_OK);
    rl_texture_release(tex);
    size_t n = 0;
    unsigned char *data = read_all(good, &n);
    unsigned char *idat = NULL;
    for (size_t i = 4; i + 4 <= n && !idat; ++i)
        if (memcmp(data + i, "IDAT", 4) == 0)
            idat = data + i - 4;
    assert_non_null(idat);
    static const unsigned char length[4] = { 0x7e, 0x00, 0x00, 0x1c };   /* big-endian, not in the CRC */
    memcpy(idat, length, 4);
    const char *bad = tmp_path("chunk_2gb.png");
    write_bytes(bad, data, n);
    tex = NULL;
    rl_clear_error();
    assert_int_equal(rl_texture_load(bad, &tex), RL_ERR_PARSE);
    assert_null(tex);
    if (!strstr(rl_last_error(), "longer than the file"))
        fail_msg("not refused by the chunk check: %s", rl_last_error());
    rl_clear_error();
}

/* PNG's CRC-32 (ISO 3309), to re-seal an edited chunk. */
static uint32_t crc32_of(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; ++i) {
        c ^= p[i];
        for (int k = 0; k < 8; ++k)
            c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
}

/* A valid PNG header (CRC right) claiming 16384x16384 pixels on a file of
 * a few hundred bytes: refused from the file's size before gigabytes are
 * allocated (issue 34). */
static void test_png_claiming_more_pixels_than_its_bytes_hold_is_refused(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(4, 4, RL_LAYER_COLOR, &img), RL_OK);
    const char *good = tmp_path("small.png");
    assert_int_equal(rl_image_write(img, good), RL_OK);
    rl_image_release(img);
    size_t n = 0;
    unsigned char *data = read_all(good, &n);
    /* Signature (8), IHDR length (4), "IHDR", width, height, ..., CRC at 29. */
    assert_memory_equal(data + 12, "IHDR", 4);
    static const unsigned char side[4] = { 0, 0, 0x40, 0 };     /* 16384, big-endian */
    memcpy(data + 16, side, 4);
    memcpy(data + 20, side, 4);
    uint32_t crc = crc32_of(data + 12, 17);
    unsigned char be[4] = { (unsigned char)(crc >> 24), (unsigned char)(crc >> 16), (unsigned char)(crc >> 8),
                            (unsigned char)crc };
    memcpy(data + 29, be, 4);
    const char *bad = tmp_path("huge.png");
    write_bytes(bad, data, n);
    rl_image *back = NULL;
    rl_clear_error();
    assert_int_equal(rl_image_read(bad, &back), RL_ERR_PARSE);
    assert_null(back);
    if (!strstr(rl_last_error(), "cannot hold"))
        fail_msg("not refused by its size: %s", rl_last_error());
    rl_clear_error();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_create_clears_every_layer),
        cmocka_unit_test(test_absurd_sizes_are_refused_with_limit),
        cmocka_unit_test(test_png_round_trip_is_exact_for_8bit_values),
        cmocka_unit_test(test_png_clamps_out_of_range_and_nan),
        cmocka_unit_test(test_png_reader_expands_16bit_and_grey_to_rgba),
        cmocka_unit_test(test_exr_round_trip_keeps_half_precision),
        cmocka_unit_test(test_unknown_extension_is_unsupported_and_writes_nothing),
        cmocka_unit_test(test_unwritable_path_is_an_io_error),
        cmocka_unit_test(test_texture_loads_png_with_uv_origin_bottom_left),
        cmocka_unit_test(test_texture_sampling_is_bilinear_with_repeat),
        cmocka_unit_test(test_corrupted_png_is_an_error_not_a_crash),
        cmocka_unit_test(test_exr_attribute_longer_than_the_file_is_refused),
        cmocka_unit_test(test_exr_chunk_longer_than_the_file_is_refused),
        cmocka_unit_test(test_png_chunk_longer_than_the_file_is_refused_by_the_texture_loader),
        cmocka_unit_test(test_png_claiming_more_pixels_than_its_bytes_hold_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
