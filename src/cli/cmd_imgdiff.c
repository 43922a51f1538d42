/*
 * amgsplat imgdiff: PSNR, SSIM and silhouette IoU of two images.
 */
#include <math.h>
#include <stdio.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat imgdiff A.png B.png [--background R,G,B] [--tolerance N] [--json]\n"
    "\n"
    "Compares two equally sized images: PSNR over RGB (dB, inf when identical), SSIM of\n"
    "luma (11x11 Gaussian window, sigma 1.5), and the IoU of their silhouettes. An image\n"
    "with any alpha below 255 takes its silhouette from alpha (alpha > 0); an opaque one\n"
    "from its background colour: --background, or by default the colour most of its four\n"
    "corner pixels share. A pixel is background when each channel is within --tolerance\n"
    "(default 8) of that colour.";

static cJSON *source_json(const asp_silhouette_info *s)
{
    cJSON *o = cJSON_CreateObject();
    cJSON_AddStringToObject(o, "source", asp_silhouette_source_name(s->source));
    if (s->source != ASP_SILHOUETTE_ALPHA)
        cJSON_AddItemToObject(o, "background",
                              cJSON_CreateIntArray((const int[]){s->background[0], s->background[1], s->background[2]}, 3));
    if (s->source == ASP_SILHOUETTE_CORNERS)
        cJSON_AddNumberToObject(o, "corners_agreeing", s->corners_agreeing);
    cJSON_AddNumberToObject(o, "pixels", (double)s->foreground);
    return o;
}

static void print_source(const asp_silhouette_info *s)
{
    printf("%s", asp_silhouette_source_name(s->source));
    if (s->source != ASP_SILHOUETTE_ALPHA)
        printf(" %u,%u,%u", s->background[0], s->background[1], s->background[2]);
    if (s->source == ASP_SILHOUETTE_CORNERS)
        printf(" (%d of 4 corners)", s->corners_agreeing);
    printf(", %zu pixels", s->foreground);
}

int cmd_imgdiff(int argc, char **argv, struct cli_env *env)
{
    const char *background = NULL;
    int tolerance = 8;
    const struct cli_option opts[] = {
        {"background", 'b', CLI_STRING, &background, "R,G,B", "background colour (0..255 or #RRGGBB) of opaque images"},
        {"tolerance", 0, CLI_INT, &tolerance, "N", "levels per channel still counted as background (default 8)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 2)
        return cli_usage_error(env, "expected two images, got %d; see 'amgsplat imgdiff -h'", npos);
    uint8_t bg[4];
    if (background && cli_parse_colour(env, "--background", background, 0, bg))
        return 2;
    if (tolerance < 0 || tolerance > 255)
        return cli_usage_error(env, "--tolerance expects 0..255, got %d", tolerance);
    asp_image a = {0}, b = {0};
    asp_error err = {0};
    double psnr = 0, ssim = 0, iou = 0;
    asp_silhouette_info sil[2];
    const asp_silhouette_desc sdesc = {.background = background ? bg : NULL, .tolerance = tolerance ? tolerance : -1};
    int status = 0;
    if (asp_image_load(&a, argv[0], &err) || asp_image_load(&b, argv[1], &err) ||
        asp_image_psnr(&a, &b, &psnr, &err) || asp_image_ssim(&a, &b, &ssim, &err) ||
        asp_image_silhouettes(&a, &b, &sdesc, &iou, sil, &err)) {
        status = cli_fail(env, &err);
    } else if (env->json) {
        cJSON *o = cJSON_CreateObject(), *sils = cJSON_CreateArray();
        cJSON_AddNumberToObject(o, "width", a.width);
        cJSON_AddNumberToObject(o, "height", a.height);
        cJSON_AddItemToObject(o, "psnr", cli_json_number("%.4f", psnr)); // null when identical (infinite)
        cJSON_AddBoolToObject(o, "identical", isinf(psnr));
        cJSON_AddItemToObject(o, "ssim", cli_json_number("%.6f", ssim));
        cJSON_AddItemToObject(o, "iou", cli_json_number("%.6f", iou));
        cJSON_AddNumberToObject(o, "tolerance", tolerance);
        cJSON_AddItemToArray(sils, source_json(&sil[0]));
        cJSON_AddItemToArray(sils, source_json(&sil[1]));
        cJSON_AddItemToObject(o, "silhouette", sils);
        status = cli_json_print(env, o);
    } else {
        printf("size %ux%u\n", a.width, a.height);
        if (isinf(psnr))
            printf("psnr inf (identical)\n");
        else
            printf("psnr %.4f dB\n", psnr);
        printf("ssim %.6f\niou  %.6f\n", ssim, iou);
        for (int k = 0; k < 2; k++) {
            printf("silhouette %c: ", k ? 'B' : 'A');
            print_source(&sil[k]);
            printf("\n");
        }
    }
    asp_image_release(&a);
    asp_image_release(&b);
    return status;
}
