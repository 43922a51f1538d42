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

static void print_source(const asp_silhouette_info *s, int json)
{
    if (json) {
        printf("{\"source\": \"%s\"", asp_silhouette_source_name(s->source));
        if (s->source != ASP_SILHOUETTE_ALPHA)
            printf(", \"background\": [%u, %u, %u]", s->background[0], s->background[1], s->background[2]);
        if (s->source == ASP_SILHOUETTE_CORNERS)
            printf(", \"corners_agreeing\": %d", s->corners_agreeing);
        printf(", \"pixels\": %zu}", s->foreground);
        return;
    }
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
        {"background", 'b', CLI_STRING, &background, "R,G,B", "background colour (0..255) of opaque images"},
        {"tolerance", 0, CLI_INT, &tolerance, "N", "levels per channel still counted as background (default 8)"},
        {0},
    };
    int npos = 0, rc = cli_parse(argc, argv, opts, usage, env, &npos);
    if (rc)
        return rc > 0 ? 0 : 2;
    if (npos != 2)
        return cli_usage_error(env, "expected two images, got %d; see 'amgsplat imgdiff -h'", npos);
    uint8_t bg[3];
    if (background) {
        double v[3];
        if (cli_parse_doubles(background, v, 3) != 3 || v[0] < 0 || v[0] > 255 || v[1] < 0 || v[1] > 255 ||
            v[2] < 0 || v[2] > 255)
            return cli_usage_error(env, "--background expects R,G,B in 0..255, got '%s'", background);
        for (int k = 0; k < 3; k++)
            bg[k] = (uint8_t)v[k];
    }
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
        printf("{\"width\": %u, \"height\": %u, \"psnr\": ", a.width, a.height);
        if (isinf(psnr))
            printf("null");
        else
            printf("%.4f", psnr);
        printf(", \"identical\": %s, \"ssim\": %.6f, \"iou\": %.6f, \"tolerance\": %d, \"silhouette\": [",
               isinf(psnr) ? "true" : "false", ssim, iou, tolerance);
        print_source(&sil[0], 1);
        printf(", ");
        print_source(&sil[1], 1);
        printf("]}\n");
    } else {
        printf("size %ux%u\n", a.width, a.height);
        if (isinf(psnr))
            printf("psnr inf (identical)\n");
        else
            printf("psnr %.4f dB\n", psnr);
        printf("ssim %.6f\niou  %.6f\n", ssim, iou);
        for (int k = 0; k < 2; k++) {
            printf("silhouette %c: ", k ? 'B' : 'A');
            print_source(&sil[k], 0);
            printf("\n");
        }
    }
    asp_image_release(&a);
    asp_image_release(&b);
    return status;
}
