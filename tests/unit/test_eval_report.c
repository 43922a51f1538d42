/* Evaluation results: CSV and JSON files, SSIM win counts and charts from a hand-made result. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <cjson/cJSON.h>

#include "harness.h"
#include "amgsplat/eval.h"

/* 1 when the JSON array holds exactly the n numbers want (NaN in want: null). */
static int numbers_are(const cJSON *a, const double *want, int n)
{
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n)
        return 0;
    for (int i = 0; i < n; i++) {
        const cJSON *v = cJSON_GetArrayItem(a, i);
        if (isnan(want[i]) ? !cJSON_IsNull(v) : !(cJSON_IsNumber(v) && v->valuedouble == want[i]))
            return 0;
    }
    return 1;
}

static asp_eval_result *make_result(void)
{
    asp_eval_result *r = asp_calloc(NULL, 1, sizeof *r);
    r->row_count = 3;
    r->views = 4;
    r->rows = asp_calloc(NULL, 3, sizeof *r->rows);
    r->ssim = asp_calloc(NULL, 12, sizeof *r->ssim);
    r->psnr = asp_calloc(NULL, 12, sizeof *r->psnr);
    const char *names[3] = {"reference", "points", "dp-normalized"};
    for (int i = 0; i < 3; i++) {
        asp_eval_row *row = &r->rows[i];
        snprintf(row->representation, sizeof row->representation, "%s", names[i]);
        snprintf(row->level_name, sizeof row->level_name, i ? "L" : "points");
        row->size = 64;
        row->primitives = i ? 8 : 1000;
        row->ssim_mean = i == 0 ? 1 : i == 1 ? 0.5 : 0.9;
        row->frame_ms = 1.5;
    }
    const double pts[4] = {0.5, 0.6, 0.95, 0.4}, dp[4] = {0.9, 0.9, 0.9, 0.9};
    for (int v = 0; v < 4; v++) {
        r->ssim[v] = 1;
        r->ssim[4 + v] = pts[v];
        r->ssim[8 + v] = dp[v];
    }
    return r;
}

static char *slurp(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return NULL;
    static char buf[65536];
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    buf[n] = 0;
    fclose(fp);
    return buf;
}

static void test_wins(void)
{
    asp_eval_result *r = make_result();
    CHECK(asp_eval_ssim_wins(r, 2, 1) == 3); /* dp beats the cut in 3 of 4 views */
    CHECK(asp_eval_ssim_wins(r, 1, 2) == 1);
    CHECK(asp_eval_ssim_wins(r, 0, 2) == 4);
    asp_eval_result_destroy(r);
    asp_eval_result_destroy(NULL);
}

static void test_csv_json(void)
{
    asp_eval_result *r = make_result();
    char csv[64], json[64];
    snprintf(csv, sizeof csv, "/tmp/asp_eval_report_%d.csv", (int)getpid());
    snprintf(json, sizeof json, "/tmp/asp_eval_report_%d.json", (int)getpid());
    asp_error err = {0};
    CHECK_OK(asp_eval_save_csv(r, csv, &err), &err);
    char *text = slurp(csv);
    CHECK(text && strncmp(text, "representation,level,level_name,size,primitives,drawn,texels,psnr_mean", 70) == 0);
    size_t lines = 0;
    for (const char *p = text; p && *p; p++)
        lines += *p == '\n';
    CHECK(lines == 4);
    CHECK(text && strstr(text, "\ndp-normalized,0,L,64,8,") != NULL);
    CHECK_OK(asp_eval_save_json(r, "m\"x", json, &err), &err);
    text = slurp(json);
    cJSON *doc = text ? cJSON_Parse(text) : NULL;
    CHECK(doc != NULL);
    const cJSON *model = cJSON_GetObjectItemCaseSensitive(doc, "model");
    CHECK(cJSON_IsString(model) && strcmp(model->valuestring, "m\"x") == 0);
    const cJSON *rows = cJSON_GetObjectItemCaseSensitive(doc, "rows");
    CHECK(cJSON_GetArraySize(rows) == 3);
    CHECK(numbers_are(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(rows, 1), "ssim_views"),
                      (const double[]){0.5, 0.6, 0.95, 0.4}, 4));
    cJSON_Delete(doc);
    unlink(csv);
    unlink(json);
    /* an unwritable path fails with ASP_EIO and names it */
    CHECK(asp_eval_save_csv(r, "/nonexistent-dir/x.csv", &err) == ASP_EIO);
    CHECK(strstr(err.msg, "/nonexistent-dir/x.csv") != NULL);
    asp_eval_result_destroy(r);
}

static void test_chart(void)
{
    asp_eval_result *r = make_result();
    asp_image img = {0};
    asp_error err = {0};
    CHECK_OK(asp_eval_chart(r, 64, 0, &img, &err), &err);
    CHECK(img.width > 0);
    asp_image_release(&img);
    CHECK_OK(asp_eval_chart(r, 64, 1, &img, &err), &err);
    asp_image_release(&img);
    CHECK(asp_eval_chart(r, 128, 0, &img, &err) == ASP_EINVAL);
    CHECK(strstr(err.msg, "128") != NULL);
    CHECK(asp_eval_chart(r, 64, 2, &img, &err) == ASP_EINVAL);
    CHECK(img.pixels == NULL);
    asp_eval_result_destroy(r);
}

/* A row without figures (issue 14: no simplified mesh fits the bytes): empty CSV fields, JSON nulls, the note. */
static void test_row_without_figures(void)
{
    asp_eval_result *r = make_result();
    asp_eval_row *row = &r->rows[2];
    snprintf(row->representation, sizeof row->representation, "mesh-bytes");
    snprintf(row->note, sizeof row->note, "texture alone 5592405 bytes exceeds 1000");
    row->psnr_mean = row->psnr_min = row->ssim_mean = row->ssim_min = NAN;
    row->iou_mean = row->iou_min = row->frame_ms = NAN;
    r->rows[1].bytes = 256;
    for (int v = 0; v < 4; v++)
        r->ssim[8 + v] = r->psnr[8 + v] = NAN;
    char csv[64], json[64];
    snprintf(csv, sizeof csv, "/tmp/asp_eval_nofig_%d.csv", (int)getpid());
    snprintf(json, sizeof json, "/tmp/asp_eval_nofig_%d.json", (int)getpid());
    asp_error err = {0};
    CHECK_OK(asp_eval_save_csv(r, csv, &err), &err);
    char *text = slurp(csv);
    CHECK(text && strstr(text, ",frame_ms,bytes,note\n") != NULL);
    CHECK(text && strstr(text, "\nmesh-bytes,0,L,64,8,0.0,0,,,,,,,,0,texture alone 5592405 bytes exceeds 1000\n"));
    CHECK(text && strstr(text, "\npoints,0,L,64,8,0.0,0,0.0000,0.0000,0.500000,0.000000,0.000000,0.000000,1.5000,256,\n"));
    CHECK_OK(asp_eval_save_json(r, NULL, json, &err), &err);
    text = slurp(json);
    cJSON *doc = text ? cJSON_Parse(text) : NULL;
    const cJSON *last = cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(doc, "rows"), 2);
    const cJSON *note = cJSON_GetObjectItemCaseSensitive(last, "note");
    CHECK(cJSON_IsString(note) && strcmp(note->valuestring, "texture alone 5592405 bytes exceeds 1000") == 0);
    CHECK(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(last, "psnr_mean")));
    CHECK(numbers_are(cJSON_GetObjectItemCaseSensitive(last, "ssim_views"), (const double[]){NAN, NAN, NAN, NAN}, 4));
    cJSON_Delete(doc);
    unlink(csv);
    unlink(json);
    /* the chart leaves the row out: the same picture as without it */
    asp_image with = {0}, without = {0};
    CHECK_OK(asp_eval_chart(r, 64, 0, &with, &err), &err);
    r->row_count = 2;
    CHECK_OK(asp_eval_chart(r, 64, 0, &without, &err), &err);
    CHECK(with.width == without.width && with.height == without.height);
    size_t differ = 0;
    for (size_t i = 0; i < (size_t)with.width * with.height * 4; i++)
        differ += with.pixels[i] != without.pixels[i];
    CHECK(differ == 0);
    asp_image_release(&with);
    asp_image_release(&without);
    asp_eval_result_destroy(r);
}

TEST_MAIN(TEST_CASE(test_wins), TEST_CASE(test_csv_json), TEST_CASE(test_chart), TEST_CASE(test_row_without_figures))
