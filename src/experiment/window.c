/*
 * The experiment for people (seed 004 2.3): a GLFW window, an instruction
 * screen before each test, keyboard-only controls (arrows or WASD, Enter when
 * recognised, the name typed in the window, Esc to abort), the red warning
 * when leaving the path. Text is stb_easy_font's quads drawn as a mesh by the
 * mesh renderer, so no GL call leaves src/render (STYLE.md 9).
 */
#include <ctype.h>
#include <math.h>
#include <string.h>
#include <strings.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_easy_font.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include "experiment/internal.h"
#include "util/banned.h"

typedef struct exp_keys {
    const char *script; /* scripted keys, one per frame; NULL = the keyboard */
    size_t at;
    char typed[16];     /* characters typed since the last poll */
    size_t ntyped;
    int enter, esc, backspace;
    int held_w, held_a, held_s, held_d;
} exp_keys;

static exp_keys *keys_of(exp_study *st)
{
    return st->window ? glfwGetWindowUserPointer((GLFWwindow *)st->window) : NULL;
}

static void on_char(GLFWwindow *w, unsigned cp)
{
    exp_keys *k = glfwGetWindowUserPointer(w);
    if (k && !k->script && cp < 128 && (isalnum((int)cp) || cp == ' ' || cp == '-') && k->ntyped + 1 < sizeof k->typed)
        k->typed[k->ntyped++] = (char)cp;
}

static void on_key(GLFWwindow *w, int key, int scancode, int act, int mods)
{
    (void)scancode;
    (void)mods;
    exp_keys *k = glfwGetWindowUserPointer(w);
    if (!k || k->script || act == GLFW_RELEASE)
        return;
    if (key == GLFW_KEY_ENTER || key == GLFW_KEY_KP_ENTER)
        k->enter = 1;
    else if (key == GLFW_KEY_ESCAPE)
        k->esc = 1;
    else if (key == GLFW_KEY_BACKSPACE)
        k->backspace = 1;
}

/* one frame of input: the script's next key, or the window's events and held keys */
static void poll(exp_study *st, exp_keys *k)
{
    GLFWwindow *w = st->window;
    k->ntyped = 0;
    k->enter = k->esc = k->backspace = 0;
    k->held_w = k->held_a = k->held_s = k->held_d = 0;
    glfwPollEvents();
    if (k->script) {
        char c = k->script[k->at];
        if (!c) {
            k->esc = 1; // the script ran out: end the session, as a person pressing Esc
            return;
        }
        k->at++;
        k->held_w = c == 'W';
        k->held_a = c == 'A';
        k->held_s = c == 'S';
        k->held_d = c == 'D';
        k->enter = c == '>';
        k->backspace = c == '<';
        k->esc = c == '!';
        if (islower((unsigned char)c))
            k->typed[k->ntyped++] = c;
        return;
    }
    k->held_w = glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_UP) == GLFW_PRESS;
    k->held_s = glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_DOWN) == GLFW_PRESS;
    k->held_a = glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_LEFT) == GLFW_PRESS;
    k->held_d = glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT) == GLFW_PRESS;
    if (glfwWindowShouldClose(w))
        k->esc = 1;
}

static void held_string(const exp_keys *k, char out[8])
{
    size_t n = 0;
    if (k->held_w)
        out[n++] = 'W';
    if (k->held_a)
        out[n++] = 'A';
    if (k->held_s)
        out[n++] = 'S';
    if (k->held_d)
        out[n++] = 'D';
    out[n] = 0;
}

/* ---------------------------------------------------------------- text as a mesh */

typedef struct exp_text {
    asp_renderer *r;
    asp_camera cam;
} exp_text;

/* stb_easy_font's quads (x right, y down, 16-byte vertices) as triangles on the plane z = 0, y up */
static int text_create(exp_study *st, const char *text, const uint8_t color[4], exp_text *out, asp_error *err)
{
    memset(out, 0, sizeof *out);
    size_t cap = 600 * strlen(text) + 4096; // stb_easy_font: at most ~270 bytes per character
    char *vbuf = asp_alloc(st->ctx, cap);
    if (!vbuf)
        return asp_error_set(err, ASP_ENOMEM, "out of memory for text");
    char *copy = asp_alloc(st->ctx, strlen(text) + 1);
    if (!copy) {
        asp_free(st->ctx, vbuf);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for text");
    }
    memcpy(copy, text, strlen(text) + 1);
    unsigned char c[4] = {color[0], color[1], color[2], color[3]};
    int quads = stb_easy_font_print(0.0f, 0.0f, copy, c, vbuf, (int)cap);
    float width = (float)stb_easy_font_width(copy), height = (float)stb_easy_font_height(copy);
    asp_free(st->ctx, copy);
    if (quads <= 0) { // an empty text: one invisible speck, so the screen is still cleared
        quads = 1;
        memset(vbuf, 0, 64);
    }
    size_t nv = 4 * (size_t)quads, nt = 2 * (size_t)quads;
    float *pos = asp_alloc(st->ctx, 12 * nv);
    uint8_t *col = asp_alloc(st->ctx, 4 * nv);
    uint32_t *tri = asp_alloc(st->ctx, 12 * nt);
    int rc = 0;
    if (!pos || !col || !tri)
        rc = asp_error_set(err, ASP_ENOMEM, "out of memory for text");
    for (size_t v = 0; v < nv && !rc; v++) {
        float xyz[3];
        memcpy(xyz, vbuf + 16 * v, 12);
        pos[3 * v] = xyz[0];
        pos[3 * v + 1] = -xyz[1];
        pos[3 * v + 2] = 0.0f;
        memcpy(&col[4 * v], vbuf + 16 * v + 12, 4);
    }
    for (size_t q = 0; q < (size_t)quads && !rc; q++) {
        uint32_t b = (uint32_t)(4 * q);
        uint32_t *t = &tri[6 * q];
        t[0] = b, t[1] = b + 1, t[2] = b + 2, t[3] = b, t[4] = b + 2, t[5] = b + 3;
    }
    if (!rc) {
        asp_render_mesh m = {.vertex_count = nv, .triangle_count = nt, .positions = pos, .colors = col,
                             .triangles = tri};
        rc = asp_mesh_renderer_create(st->gl, &m, NULL, &out->r, err);
    }
    asp_free(st->ctx, vbuf);
    asp_free(st->ctx, pos);
    asp_free(st->ctx, col);
    asp_free(st->ctx, tri);
    if (rc)
        return rc;
    /* fit the block of text (width x height font units) into the window, seen straight on */
    uint32_t fw = 0, fh = 0;
    asp_gl_context_framebuffer_size(st->gl, &fw, &fh);
    float aspect = fh ? (float)fw / (float)fh : 1.6f;
    asp_camera_init(&out->cam);
    float w = width > 1.0f ? width : 1.0f, h = height > 1.0f ? height : 1.0f;
    float center[3] = {0.5f * w, -0.5f * h, 0.0f};
    float radius = 0.55f * (w / aspect > h ? w / aspect : h);
    asp_camera_fit(&out->cam, center, radius, aspect);
    out->cam.target[0] = center[0];
    out->cam.target[1] = center[1] - 0.0f;
    return 0;
}

/* draws the text and shows it; with png, also writes what the window shows there */
static int text_draw_png(exp_study *st, exp_text *t, const uint8_t bg[4], const char *png, asp_error *err)
{
    asp_render_desc rd = {.flags = ASP_RENDER_UNLIT};
    memcpy(rd.background, bg, 4);
    int rc = asp_render_frame(st->gl, t->r, &t->cam, &rd, err);
    if (!rc && png) {
        asp_image img = {0};
        rc = asp_gl_context_read_window(st->gl, &img, err);
        if (!rc)
            rc = asp_image_save_png(&img, png, err);
        asp_image_release(&img);
    }
    if (!rc)
        asp_gl_context_swap_buffers(st->gl);
    return rc;
}

static int text_draw(exp_study *st, exp_text *t, const uint8_t bg[4], asp_error *err)
{
    return text_draw_png(st, t, bg, NULL, err);
}

static void text_destroy(exp_text *t)
{
    asp_renderer_destroy(t->r);
    t->r = NULL;
}

/* ---------------------------------------------------------------- window */

int asp__exp_window_open(exp_study *st, asp_error *err)
{
    asp_gl_context_desc gd = {.width = st->width, .height = st->height, .title = "amgsplat experiment"};
    int rc = asp_gl_context_create_window(&gd, st->ctx, &st->gl, err);
    if (rc)
        return rc;
    exp_keys *k = asp_calloc(st->ctx, 1, sizeof *k);
    if (!k) {
        asp_gl_context_destroy(st->gl);
        st->gl = NULL;
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    }
    k->script = st->desc->keys;
    st->window = asp_gl_context_window(st->gl);
    glfwSetWindowUserPointer(st->window, k);
    glfwSetCharCallback(st->window, on_char);
    glfwSetKeyCallback(st->window, on_key);
    return 0;
}

void asp__exp_window_close(exp_study *st)
{
    if (st->window) {
        exp_keys *k = keys_of(st);
        glfwSetWindowUserPointer(st->window, NULL);
        asp_free(st->ctx, k);
    }
    st->window = NULL;
}

static const char *instructions(asp_experiment_test test)
{
    switch (test) {
    case ASP_EXPERIMENT_FAR:
    case ASP_EXPERIMENT_NEAR:
        return "OBJECT RECOGNITION\n\n"
               "An object appears. Turn it with the arrow keys\n"
               "(or W A S D); you cannot come closer.\n\n"
               "Press ENTER as soon as you know what it is,\n"
               "then type its name and press ENTER.\n\n"
               "ENTER: start      ESC: stop the session";
    case ASP_EXPERIMENT_LOWSPEED:
        return "WALKING\n\n"
               "Walk along the sandy path to its end.\n"
               "UP or W: walk   LEFT/RIGHT or A/D: turn\n"
               "DOWN or S: step back\n\n"
               "Leaving the path flashes red and puts you back on it.\n\n"
               "ENTER: start      ESC: stop the session";
    default:
        return "FLYING\n\n"
               "Fly the ship through the canyon to its end.\n"
               "LEFT/RIGHT or A/D: steer   UP or W: faster\n\n"
               "Do not touch the walls.\n\n"
               "ENTER: start      ESC: stop the session";
    }
}

int asp__exp_window_instructions(exp_study *st, asp_experiment_test test, int practice, asp_error *err)
{
    static const uint8_t white[4] = {235, 235, 235, 255}, bg[4] = {30, 32, 40, 255};
    char text[768];
    snprintf(text, sizeof text, "%s%s", practice ? "PRACTICE (not recorded)\n\n" : "", instructions(test));
    exp_text t;
    int rc = text_create(st, text, white, &t, err);
    exp_keys *k = keys_of(st);
    char png[2200];
    snprintf(png, sizeof png, "%s/instructions-%s.png", st->desc->screenshots_dir ? st->desc->screenshots_dir : "",
             asp_experiment_test_name(test));
    for (int first = 1; !rc; first = 0) {
        // shown before any key counts, so the screen is seen (and saved) even when Enter comes at once
        rc = text_draw_png(st, &t, bg, first && st->desc->screenshots_dir && !practice ? png : NULL, err);
        poll(st, k);
        if (k->esc) {
            st->aborted = 1;
            break;
        }
        if (k->enter)
            break;
    }
    text_destroy(&t);
    return rc;
}

/* draws a frame of the run into the window; blank draws the background only */
static int window_frame(exp_run *r, const asp_camera *cam, const uint8_t bg[4], double *ms, size_t *drawn,
                        asp_error *err)
{
    exp_study *st = r->st;
    double t0 = asp_time_now();
    asp_render_desc rd = {.light_elevation = 45.0f, .flags = ASP_RENDER_WAIT};
    memcpy(rd.background, bg, 4);
    int rc = 0;
    if (r->cond == ASP_EXPERIMENT_BLANK) {
        static const uint8_t none[4] = {0, 0, 0, 0};
        exp_text t;
        rc = text_create(st, "", none, &t, err);
        if (!rc) {
            rc = text_draw(st, &t, bg, err);
            text_destroy(&t);
        }
        *drawn = 0;
    } else {
        rc = asp_render_frame(st->gl, r->p->renderer[r->cond], cam, &rd, err);
        *drawn = asp_renderer_count(r->p->renderer[r->cond]);
        if (!rc)
            asp_gl_context_swap_buffers(st->gl);
    }
    *ms = 1000.0 * (asp_time_now() - t0);
    return rc;
}

/* real time for people, bounded so a stall (a dragged window) does not jump the walker through rock */
static double frame_dt(double *last)
{
    double now = asp_time_now(), dt = *last > 0.0 ? now - *last : FIXED_DT;
    *last = now;
    return dt < 0.001 ? 0.001 : dt > 0.1 ? 0.1 : dt;
}

int asp__exp_window_navigation(exp_run *r, asp_error *err)
{
    exp_study *st = r->st;
    exp_prepared *p = r->p;
    const asp_experiment_world *w = &p->world;
    exp_keys *k = keys_of(st);
    int high = r->test == ASP_EXPERIMENT_HIGHSPEED;
    float pitch = (high ? -8.0f : -14.0f) * DEG;
    float x = w->path[0], z = w->path[2], along = 0.0f;
    float yaw = atan2f(w->path[3] - w->path[0], w->path[5] - w->path[2]);
    double t = 0.0, last = 0.0, warning_until = -1.0;
    double limit = p->scene.time_limit * (r->log.fp ? 1.0 : 0.25) * (st->desc->short_tests ? 0.1 : 1.0);
    static const uint8_t red[4] = {230, 40, 30, 255};
    int rc = 0;
    for (size_t i = 0; !rc && t < limit && along < 0.995f; i++) {
        poll(st, k);
        if (k->esc) {
            st->aborted = 1;
            rc = asp__exp_write_event(r, t, "abort", NULL, err);
            break;
        }
        float ground = asp_experiment_world_height(w, x, z);
        float eye[3] = {x, ground + p->scene.eye_height, z};
        float dir[3] = {sinf(yaw), 0.0f, cosf(yaw)};
        uint32_t fw = 0, fh = 0;
        asp_gl_context_framebuffer_size(st->gl, &fw, &fh);
        asp_camera cam;
        asp__exp_first_person(&cam, p->origin[r->cond], eye, yaw, pitch, fh ? (float)fw / (float)fh : 1.6f,
                              1.5f * w->size);
        double ms = 0.0;
        size_t drawn = 0;
        /* seed 004 2.3: a red warning light while off the path */
        rc = window_frame(r, &cam, t < warning_until ? red : asp__exp_sky, &ms, &drawn, err);
        char held[8];
        held_string(k, held);
        float logged[3] = {x, ground, z};
        if (!rc)
            rc = asp__exp_write_frame(r, i, t, ms, logged, dir, drawn, held, NULL, err);
        double dt = frame_dt(&last);
        double turn = (k->held_a ? 1.2 : 0.0) - (k->held_d ? 1.2 : 0.0);
        double speed = high ? p->scene.speed * (k->held_w ? 1.5 : 1.0)
                            : (k->held_w ? p->scene.speed : k->held_s ? -0.5 * p->scene.speed : 0.0);
        size_t before = r->res.off_path;
        t += dt;
        if (!rc)
            rc = asp__exp_nav_move(r, &x, &z, &yaw, turn, speed, dt, t, &along, err);
        if (r->res.off_path != before)
            warning_until = t + 0.4;
    }
    r->res.progress = along;
    return rc;
}

int asp__exp_window_recognition(exp_run *r, asp_error *err)
{
    exp_study *st = r->st;
    exp_prepared *p = r->p;
    exp_keys *k = keys_of(st);
    static const uint8_t white[4] = {235, 235, 235, 255};
    float yaw = 30.0f, pitch = 15.0f;
    double t = 0.0, last = 0.0, t_recognised = -1.0;
    char name[32] = "";
    size_t len = 0;
    int rc = 0;
    for (size_t i = 0; !rc; i++) {
        poll(st, k);
        if (k->esc) {
            st->aborted = 1;
            rc = asp__exp_write_event(r, t, "abort", NULL, err);
            break;
        }
        uint32_t fw = 0, fh = 0;
        asp_gl_context_framebuffer_size(st->gl, &fw, &fh);
        asp_camera cam;
        asp__exp_object_camera(&cam, p, p->origin[r->cond], yaw, pitch, p->scene.distance_radii,
                               fh ? (float)fw / (float)fh : 1.6f);
        double ms = 0.0;
        size_t drawn = 0;
        if (t_recognised < 0.0) {
            rc = window_frame(r, &cam, asp__exp_backdrop, &ms, &drawn, err);
        } else {
            /* the naming prompt, typed in the window (seed 004 2.3's dialog box) */
            char prompt[96];
            snprintf(prompt, sizeof prompt, "What is it? Type the name, then ENTER:\n\n%s_", name);
            exp_text tx;
            double t0 = asp_time_now();
            rc = text_create(st, prompt, white, &tx, err);
            if (!rc) {
                rc = text_draw(st, &tx, asp__exp_backdrop, err);
                text_destroy(&tx);
            }
            ms = 1000.0 * (asp_time_now() - t0);
        }
        float eye[3];
        asp_camera_eye(&cam, eye);
        float dir[3] = {cam.target[0] - eye[0], cam.target[1] - eye[1], cam.target[2] - eye[2]};
        float n = sqrtf(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        for (int c = 0; c < 3; c++) {
            dir[c] = n > 0.0f ? dir[c] / n : 0.0f;
            eye[c] = (float)(eye[c] + p->origin[r->cond][c]);
        }
        char held[8];
        held_string(k, held);
        float rot[2] = {yaw, pitch};
        if (!rc)
            rc = asp__exp_write_frame(r, i, t, ms, eye, dir, drawn, held, rot, err);
        double dt = frame_dt(&last);
        t += dt;
        if (rc)
            break;
        if (t_recognised < 0.0) {
            yaw += (float)(60.0 * dt) * (float)(k->held_d - k->held_a);
            pitch += (float)(45.0 * dt) * (float)(k->held_w - k->held_s);
            pitch = pitch > 80.0f ? 80.0f : pitch < -80.0f ? -80.0f : pitch;
            if (k->enter) {
                t_recognised = t;
                rc = asp__exp_write_event(r, t, "recognised", NULL, err);
            }
            continue;
        }
        for (size_t c = 0; c < k->ntyped && len + 1 < sizeof name; c++)
            name[len++] = k->typed[c];
        name[len] = 0;
        if (k->backspace && len > 0)
            name[--len] = 0;
        if (k->enter && len > 0) {
            snprintf(r->res.answer, sizeof r->res.answer, "%s", name);
            r->res.correct = strcasecmp(name, p->model_name) == 0;
            r->res.recognition_s = t_recognised;
            r->res.naming_s = t - t_recognised;
            rc = asp__exp_write_event(r, t, "answer", name, err);
            break;
        }
    }
    return rc;
}
