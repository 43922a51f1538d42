/*
 * The experiment for people (seed 004 2.3) as an input source of the trial
 * loops (trial.c): a GLFW window, an instruction screen before each test,
 * keyboard-only controls (arrows or WASD, Enter when recognised, the name
 * typed in the window, Esc to abort), frames shown as they are drawn and timed
 * by the wall clock. Text is the render module's one text overlay
 * (asp_text_overlay), so no GL call leaves src/render (STYLE.md 9).
 */
#include <ctype.h>
#include <math.h>
#include <string.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

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
static void poll_keys(GLFWwindow *w, exp_keys *k)
{
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


typedef struct person {
    exp_source base;
    GLFWwindow *window;
    exp_keys keys;               /* the window's user pointer */
    asp_text_overlay *overlay;
    double last;                 /* wall clock of the last frame; 0 = none yet */
    char name[32];               /* the name typed so far */
    size_t len;
} person;

/* ---------------------------------------------------------------- text screens */

/*
 * A screen of text: the window covered with bg and the text block centred,
 * as large as fits in nine tenths of it, so it reads at any window size;
 * with png, what the window shows is saved there too. Then shown.
 */
static int text_screen(person *ps, const char *text, const uint8_t bg[4], const char *png, asp_error *err)
{
    exp_study *st = ps->base.st;
    uint32_t fw = 0, fh = 0;
    asp_gl_context_framebuffer_size(st->gl, &fw, &fh);
    float w1, h1;
    asp_text_overlay_measure(text, 1.0f, &w1, &h1);
    float scale = fminf(0.9f * (float)fw / w1, 0.9f * (float)fh / h1);
    scale = scale > 0.0f ? scale : 1.0f;
    float w, h;
    asp_text_overlay_measure(text, scale, &w, &h);
    static const uint8_t white[4] = {235, 235, 235, 255};
    asp_text_overlay_desc od = {.x = floorf(0.5f * ((float)fw - w)), .y = floorf(0.5f * ((float)fh - h)),
                                .scale = scale};
    memcpy(od.color, white, 4);
    memcpy(od.box, bg, 4); // the box is the screen
    memcpy(od.fill, bg, 4);
    int rc = asp_text_overlay_draw(ps->overlay, text, &od, err);
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

/* the instruction screen until Enter (or Esc, which ends the session) */
static int intro(exp_source *s, asp_experiment_test test, int practice, asp_error *err)
{
    person *ps = (person *)s;
    exp_study *st = s->st;
    static const uint8_t bg[4] = {30, 32, 40, 255};
    char text[768];
    char png[2200];
    const char *shots = st->desc->screenshots_dir;
    if (practice == 2) {
        /* after the practice: the subject knows that what follows counts (seed 004 2.3's measured tests) */
        snprintf(text, sizeof text, "PRACTICE OVER\n\n"
                                    "You have walked and flown once.\n"
                                    "From now on every test is recorded.\n\n"
                                    "ENTER: start the tests      ESC: stop the session");
        snprintf(png, sizeof png, "%s/practice-over.png", shots ? shots : "");
    } else {
        snprintf(text, sizeof text, "%s%s", practice ? "PRACTICE (not recorded)\n\n" : "", instructions(test));
        snprintf(png, sizeof png, "%s/%s-%s.png", shots ? shots : "", practice ? "practice" : "instructions",
                 asp_experiment_test_name(test));
    }
    int rc = 0;
    for (int first = 1; !rc; first = 0) {
        // shown before any key counts, so the screen is seen (and saved) even when Enter comes at once
        rc = text_screen(ps, text, bg, first && shots ? png : NULL, err);
        poll_keys(ps->window, &ps->keys);
        if (ps->keys.esc) {
            st->aborted = 1;
            break;
        }
        if (ps->keys.enter)
            break;
    }
    return rc;
}

/* ---------------------------------------------------------------- the source */

static int poll(exp_source *s)
{
    person *ps = (person *)s;
    poll_keys(ps->window, &ps->keys);
    return ps->keys.esc;
}

static float aspect(exp_source *s)
{
    uint32_t fw = 0, fh = 0;
    asp_gl_context_framebuffer_size(s->st->gl, &fw, &fh);
    return fh ? (float)fw / (float)fh : 1.6f;
}

/* the frame in the window; blank: the background only; naming: the prompt with the name typed so far */
static int show(exp_source *s, exp_run *r, const asp_camera *cam, const uint8_t bg[4], int naming, double *ms,
                size_t *drawn, asp_error *err)
{
    person *ps = (person *)s;
    exp_study *st = s->st;
    double t0 = asp_time_now();
    int rc = 0;
    *drawn = 0;
    if (naming) {
        /* the naming prompt, typed in the window (seed 004 2.3's dialog box) */
        char prompt[96];
        snprintf(prompt, sizeof prompt, "What is it? Type the name, then ENTER:\n\n%s_", ps->name);
        rc = text_screen(ps, prompt, bg, NULL, err);
    } else if (r->cond == ASP_EXPERIMENT_BLANK) {
        rc = text_screen(ps, "", bg, NULL, err);
    } else {
        asp_render_desc rd = {.light_elevation = 45.0f, .flags = ASP_RENDER_WAIT};
        memcpy(rd.background, bg, 4);
        rc = asp_render_frame(st->gl, r->p->renderer[r->cond], cam, &rd, err);
        *drawn = asp_renderer_count(r->p->renderer[r->cond]);
        if (!rc)
            asp_gl_context_swap_buffers(st->gl);
    }
    *ms = 1000.0 * (asp_time_now() - t0);
    return rc;
}

/* real time for people, bounded so a stall (a dragged window) does not jump the walker through rock */
static double step(exp_source *s, double ms)
{
    (void)ms;
    person *ps = (person *)s;
    double now = asp_time_now(), dt = ps->last > 0.0 ? now - ps->last : FIXED_DT;
    ps->last = now;
    return dt < 0.001 ? 0.001 : dt > 0.1 ? 0.1 : dt;
}

static float walk_begin(exp_source *s, exp_run *r)
{
    (void)r;
    ((person *)s)->last = 0.0;
    return 0.0f; // a person starts facing along the path
}

static void walk(exp_source *s, exp_run *r, double *turn, double *speed, char keys[8])
{
    const exp_keys *k = &((person *)s)->keys;
    double v = r->p->scene.speed;
    *turn = (k->held_a ? 1.2 : 0.0) - (k->held_d ? 1.2 : 0.0);
    *speed = r->test == ASP_EXPERIMENT_HIGHSPEED ? v * (k->held_w ? 1.5 : 1.0)
                                                 : (k->held_w ? v : k->held_s ? -0.5 * v : 0.0);
    held_string(k, keys);
}

static void look_begin(exp_source *s, exp_run *r, float *yaw, float *pitch)
{
    (void)r;
    person *ps = (person *)s;
    ps->last = 0.0;
    ps->name[0] = 0;
    ps->len = 0;
    *yaw = 30.0f;
    *pitch = 15.0f;
}

static void look_keys(exp_source *s, int deciding, char keys[8])
{
    (void)deciding;
    held_string(&((person *)s)->keys, keys);
}

/* the keys turn the object; Enter: recognised */
static int look(exp_source *s, exp_run *r, double t, double dt, float *yaw, float *pitch)
{
    (void)r;
    (void)t;
    const exp_keys *k = &((person *)s)->keys;
    *yaw += (float)(60.0 * dt) * (float)(k->held_d - k->held_a);
    *pitch += (float)(45.0 * dt) * (float)(k->held_w - k->held_s);
    *pitch = *pitch > 80.0f ? 80.0f : *pitch < -80.0f ? -80.0f : *pitch;
    return k->enter;
}

/* the name as typed; Enter with a name: answered */
static int name(exp_source *s, exp_run *r, double t, double t_recognised, char answer[32])
{
    (void)r;
    (void)t;
    (void)t_recognised;
    person *ps = (person *)s;
    const exp_keys *k = &ps->keys;
    for (size_t c = 0; c < k->ntyped && ps->len + 1 < sizeof ps->name; c++)
        ps->name[ps->len++] = k->typed[c];
    ps->name[ps->len] = 0;
    if (k->backspace && ps->len > 0)
        ps->name[--ps->len] = 0;
    if (!(k->enter && ps->len > 0))
        return 0;
    snprintf(answer, 32, "%s", ps->name);
    return 1;
}

static void close_person(exp_source *s)
{
    person *ps = (person *)s;
    asp_text_overlay_destroy(ps->overlay);
    glfwSetWindowUserPointer(ps->window, NULL);
    asp_free(s->st->ctx, ps);
}

static const exp_source_ops person_ops = {
    .poll = poll,
    .aspect = aspect,
    .show = show,
    .step = step,
    .walk_begin = walk_begin,
    .walk = walk,
    .look_begin = look_begin,
    .look_keys = look_keys,
    .look = look,
    .name = name,
    .intro = intro,
    .close = close_person,
};

int asp__exp_person_open(exp_study *st, exp_source **out, asp_error *err)
{
    person *ps = asp_calloc(st->ctx, 1, sizeof *ps);
    if (!ps)
        return asp_error_set(err, ASP_ENOMEM, "out of memory");
    asp_gl_context_desc gd = {.width = st->width, .height = st->height, .title = "amgsplat experiment"};
    int rc = asp_gl_context_create_window(&gd, st->ctx, &st->gl, err);
    if (!rc)
        rc = asp_text_overlay_create(st->gl, &ps->overlay, err);
    if (rc) {
        asp_gl_context_destroy(st->gl);
        st->gl = NULL;
        asp_free(st->ctx, ps);
        return rc;
    }
    ps->base = (exp_source){.ops = &person_ops, .st = st, .warns = 1};
    ps->keys.script = st->desc->keys;
    ps->window = asp_gl_context_window(st->gl);
    glfwSetWindowUserPointer(ps->window, &ps->keys);
    glfwSetCharCallback(ps->window, on_char);
    glfwSetKeyCallback(ps->window, on_key);
    *out = &ps->base;
    return 0;
}
