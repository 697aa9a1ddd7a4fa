/* fovea — libpng's error handling as the image writer (image_io.c) and the metadata reader
 * (image_meta.c) use its full API: an error longjmps back to the caller's setjmp with libpng's
 * message kept; warnings are dropped (the caller decides what is wrong with a file). */
#ifndef FV_FILM_PNG_ERRORS_H
#define FV_FILM_PNG_ERRORS_H

#include <png.h>
#include <setjmp.h>
#include <stdio.h>

typedef struct fv_png_ctx {
    jmp_buf jb;
    char msg[200];
} fv_png_ctx;

static inline void fv_png_on_error(png_structp png, png_const_charp msg)
{
    fv_png_ctx *c = png_get_error_ptr(png);
    snprintf(c->msg, sizeof c->msg, "%s", msg ? msg : "libpng failed");
    longjmp(c->jb, 1);
}

static inline void fv_png_on_warning(png_structp png, png_const_charp msg) { (void)png, (void)msg; }

#endif
