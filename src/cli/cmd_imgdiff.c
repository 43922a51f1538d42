/*
 * amgsplat imgdiff: PSNR, SSIM and silhouette IoU of two images.
 */
#include <math.h>
#include <stdio.h>

#include "cli/cli.h"
#include "cli/commands.h"
#include "util/banned.h"

static const char usage[] =
    "usage: amgsplat imgdiff A.png B.png [--background r,g,b] [--json]\n"
    "\n"
    "Compares two equally sized images: PSNR over RGB (dB, inf when identical), SSIM of\n"
    "luma (11x11 Gaussian window, sigma 1.5), and the IoU of their silhouettes. The\n"
    "silhouette is the non-transparent pixels, or with --background the pixels whose\n"
    "colour differs from that background.";

int cmd_imgdiff(int argc, char **argv, struct cli_env *env)
{
    const char *background = NULL;
    const struct cli_option opts[] = {
        {"background", 'b', CLI_STRING, &background, "R,G,B", "background colour (0..255) for the silhouette"},
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
    asp_image a = {0}, b = {0};
    asp_error err = {0};
    double psnr = 0, ssim = 0, iou = 0;
    int status = 0;
    if (asp_image_load(&a, argv[0], &err) || asp_image_load(&b, argv[1], &err) ||
        asp_image_psnr(&a, &b, &psnr, &err) || asp_image_ssim(&a, &b, &ssim, &err) ||
        asp_image_silhouette_iou(&a, &b, background ? bg : NULL, &iou, &err)) {
        status = cli_fail(env, &err);
    } else if (env->json) {
        printf("{\"width\": %u, \"height\": %u, \"psnr\": ", a.width, a.height);
        if (isinf(psnr))
            printf("null");
        else
            printf("%.4f", psnr);
        printf(", \"identical\": %s, \"ssim\": %.6f, \"iou\": %.6f}\n", isinf(psnr) ? "true" : "false", ssim, iou);
    } else {
        printf("size %ux%u\n", a.width, a.height);
        if (isinf(psnr))
            printf("psnr inf (identical)\n");
        else
            printf("psnr %.4f dB\n", psnr);
        printf("ssim %.6f\niou  %.6f\n", ssim, iou);
    }
    asp_image_release(&a);
    asp_image_release(&b);
    return status;
}
