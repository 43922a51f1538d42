/*
 * One frame into an asp_image: clear the offscreen target, let the renderer
 * draw with depth testing into the sRGB colour buffer, resolve multisampling,
 * read back and flip to rows-top-first. Pajarola et al. 2003 section 5.3 draw
 * opaque surfels with the depth buffer deciding visibility; so do we.
 */
#include <math.h>
#include <string.h>

#include "render/internal.h"
#include "util/child_process.h"
#include "util/banned.h"

enum { DEFAULT_SIZE = 512, MAX_SIDE = 16384 };

static const double deg = 3.14159265358979323846 / 180.0;

static void make_frame(const asp_camera *cam, const asp_render_desc *d, uint32_t w, uint32_t h, asp__frame *f)
{
    memset(f, 0, sizeof *f);
    asp_camera_view_matrix(cam, f->view);
    asp_camera_projection_matrix(cam, f->proj);
    asp_camera_eye(cam, f->eye);
    // eye coordinates: the light at azimuth 0, elevation 0 shines along the view direction
    double az = d->light_azimuth * deg, el = d->light_elevation * deg;
    f->light_eye[0] = (float)(sin(az) * cos(el));
    f->light_eye[1] = (float)sin(el);
    f->light_eye[2] = (float)(cos(az) * cos(el));
    f->flags = d->flags;
    f->width = w;
    f->height = h;
}

/*
 * The framebuffer holds colour premultiplied by coverage (uncovered samples
 * are the premultiplied background), so edge pixels over a transparent
 * background come out darkened; dividing by alpha in linear light restores
 * straight alpha as PNG expects.
 */
static void unpremultiply(asp_image *img, const uint8_t bg[4])
{
    float lin[256];
    for (int i = 0; i < 256; i++)
        lin[i] = asp__srgb_to_linear((uint8_t)i);
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++) {
        uint8_t *p = img->pixels + 4 * i;
        if (p[3] == 255)
            continue;
        if (p[3] == 0) {
            memcpy(p, bg, 4); // nothing drawn: report the background as given
            continue;
        }
        float a = p[3] / 255.0f;
        for (int c = 0; c < 3; c++)
            p[c] = asp__linear_to_srgb(lin[p[c]] / a);
    }
}

void asp__gl_attrib_buffer(asp__gl_vertex_array vao, GLuint attr, asp__gl_buffer *buf, const void *data, size_t bytes,
                           GLint comps, GLenum type, GLboolean normalized, GLsizei stride, GLuint divisor)
{
    glCreateBuffers(1, &buf->id);
    glNamedBufferStorage(buf->id, (GLsizeiptr)bytes, data, 0);
    glVertexArrayVertexBuffer(vao.id, attr, buf->id, 0, stride);
    glVertexArrayAttribFormat(vao.id, attr, comps, type, normalized, 0);
    glVertexArrayAttribBinding(vao.id, attr, attr);
    glVertexArrayBindingDivisor(vao.id, attr, divisor);
    glEnableVertexArrayAttrib(vao.id, attr);
}

static void clear_target(GLuint fbo, const uint8_t bg[4])
{
    // stored as given (sRGB writes are off): premultiplied in linear light, encoded
    float a = bg[3] / 255.0f;
    GLfloat color[4];
    for (int c = 0; c < 3; c++)
        color[c] = asp__linear_to_srgb(asp__srgb_to_linear(bg[c]) * a) / 255.0f;
    color[3] = a;
    GLfloat depth = 1.0f;
    glDisable(GL_FRAMEBUFFER_SRGB);
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, color);
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &depth);
}

/* Clears fbo and lets the renderer draw into it with depth testing, in linear light. */
static int draw_into(asp_gl_context *gl, asp_renderer *r, const asp__frame *f, const uint8_t bg[4], GLuint fbo,
                     asp_error *err)
{
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, (GLsizei)f->width, (GLsizei)f->height);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE); // discs are two-sided
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    clear_target(fbo, bg);
    glEnable(GL_FRAMEBUFFER_SRGB);
    int rc = r->vt->draw(r, f, err);
    if (rc)
        return rc;
    return asp__gl_check(gl, "draw the frame", err);
}

static int read_back(asp_gl_context *gl, const asp__frame *f, asp_image *img, asp_error *err)
{
    asp__gl_target *t = &gl->target;
    GLuint read_fbo = t->fbo.id;
    if (t->resolve_fbo.id) {
        // with sRGB writes on, drivers average multisamples in linear light
        glBlitNamedFramebuffer(t->fbo.id, t->resolve_fbo.id, 0, 0, (GLint)f->width, (GLint)f->height, 0, 0,
                               (GLint)f->width, (GLint)f->height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        read_fbo = t->resolve_fbo.id;
    }
    // off for the read: the stored bytes are already sRGB-encoded, which is what the image holds
    glDisable(GL_FRAMEBUFFER_SRGB);
    glNamedFramebufferReadBuffer(read_fbo, GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, read_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadnPixels(0, 0, (GLsizei)f->width, (GLsizei)f->height, GL_RGBA, GL_UNSIGNED_BYTE,
                  (GLsizei)(4 * (size_t)f->width * f->height), img->pixels);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return asp__gl_check(gl, "read back the image", err);
}

/* Checks the request and fills the frame; samples is what the context can do. */
static int prepare(asp_gl_context *gl, const asp_renderer *r, const asp_camera *cam, const asp_render_desc *desc,
                   uint32_t w, uint32_t h, asp__frame *frame, uint32_t *samples, asp_error *err)
{
    ASP_ASSERT(r->gl == gl);
    *samples = 1; // defined on the error returns too, so no caller path reads it unset
    uint32_t limit = gl->max_size > 0 && (uint32_t)gl->max_size < MAX_SIDE ? (uint32_t)gl->max_size : MAX_SIDE;
    if (w == 0 || h == 0 || w > limit || h > limit)
        return asp_error_set(err, ASP_EINVAL, "image size %ux%u is outside 1..%u, the limit of this GL context", w,
                             h, limit);
    if (!(cam->distance > 0) || !(cam->fov_y > 0 && cam->fov_y < 180) || !(cam->aspect > 0) ||
        !(cam->z_near > 0 && cam->z_far > cam->z_near))
        return asp_error_set(err, ASP_EINVAL,
                             "invalid camera: distance %g, fov_y %g, aspect %g, near %g, far %g (expected "
                             "distance > 0, 0 < fov_y < 180, aspect > 0, 0 < near < far)",
                             cam->distance, cam->fov_y, cam->aspect, cam->z_near, cam->z_far);
    *samples = desc->samples > 1 ? desc->samples : 1;
    if (*samples > (uint32_t)gl->max_samples)
        *samples = (uint32_t)gl->max_samples;
    make_frame(cam, desc, w, h, frame);
    // issue #31: llvmpipe compiles its draw code now, and crashes when that allocation fails (ulimit -v)
    int rc = asp__address_space_headroom(ASP_GL_DRAW_HEADROOM, "drawing (the GL driver's code generation)", err);
    if (rc)
        return rc;
    rc = asp__gl_ensure_current(gl, err);
    if (rc)
        return rc;
    asp__gl_clear_errors(gl);
    return 0;
}

int asp_render_frame(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, const asp_render_desc *desc,
                     asp_error *err)
{
    ASP_ASSERT(gl && r && cam);
    static const asp_render_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    uint32_t w = desc->width, h = desc->height, samples;
    if (gl->backend == ASP__GL_GLFW && (w == 0 || h == 0))
        asp_gl_context_framebuffer_size(gl, &w, &h);
    w = w ? w : DEFAULT_SIZE;
    h = h ? h : DEFAULT_SIZE;
    asp__frame frame;
    int rc = prepare(gl, r, cam, desc, w, h, &frame, &samples, err);
    if (rc)
        return rc;
    GLuint fbo = 0; // the window's back buffer
    if (gl->backend != ASP__GL_GLFW) {
        rc = asp__gl_target_ensure(gl, w, h, samples, err);
        if (rc)
            return rc;
        fbo = gl->target.fbo.id;
    }
    rc = draw_into(gl, r, &frame, desc->background, fbo, err);
    if (!rc && (desc->flags & ASP_RENDER_WAIT))
        glFinish();
    return rc;
}

int asp_render_to_image(asp_gl_context *gl, asp_renderer *r, const asp_camera *cam, const asp_render_desc *desc,
                        asp_image *out, asp_error *err)
{
    ASP_ASSERT(gl && r && cam && out);
    static const asp_render_desc zero_desc;
    if (!desc)
        desc = &zero_desc;
    uint32_t w = desc->width ? desc->width : DEFAULT_SIZE, h = desc->height ? desc->height : DEFAULT_SIZE, samples;
    asp__frame frame;
    int rc = prepare(gl, r, cam, desc, w, h, &frame, &samples, err);
    if (rc)
        return rc;
    rc = asp__gl_target_ensure(gl, w, h, samples, err);
    if (rc)
        return rc;
    asp_image img;
    rc = asp_image_init(&img, w, h, err);
    if (rc)
        return rc;
    uint8_t *row = asp_alloc(&gl->actx, 4 * (size_t)w);
    if (!row) {
        asp_image_release(&img);
        return asp_error_set(err, ASP_ENOMEM, "out of memory for a %ux%u image", w, h);
    }
    rc = draw_into(gl, r, &frame, desc->background, gl->target.fbo.id, err);
    if (!rc)
        rc = read_back(gl, &frame, &img, err);
    if (rc) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        asp_free(&gl->actx, row);
        asp_image_release(&img);
        return rc;
    }
    asp__image_flip_rows(&img, row);
    asp_free(&gl->actx, row);
    if (desc->background[3] < 255)
        unpremultiply(&img, desc->background);
    *out = img;
    return 0;
}
