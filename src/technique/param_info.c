/* fovea — a method parameter's description as text (fovea/technique.h, fv_param_info): the line
 * `fovea methods NAME` prints for each entry of a class's parameter table, so no help text is
 * written by hand beside the table it would have to agree with.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fovea/technique.h"

const char *fv_param_type_name(fv_param_type type)
{
    switch (type) {
    case FV_PARAM_INT: return "int";
    case FV_PARAM_FLOAT: return "float";
    case FV_PARAM_BOOL: return "bool";
    case FV_PARAM_CHOICE: return "choice";
    case FV_PARAM_STRING: return "string";
    }
    return "?";
}

/* Appends to buf[*len..n) like snprintf, keeping *len the length the whole text would have. */
static void add(char *buf, size_t n, int *len, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static void add(char *buf, size_t n, int *len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    size_t at = (size_t)*len < n ? (size_t)*len : n;
    int k = vsnprintf(buf ? buf + at : NULL, buf ? n - at : 0, fmt, ap);
    va_end(ap);
    if (k > 0) *len += k;
}

int fv_param_info_format(const fv_param_info *p, char *buf, size_t n)
{
    if (buf && n) buf[0] = '\0';
    if (!p) return 0;
    int len = 0;
    add(buf, n, &len, "%s=", p->key);
    if (p->choices) {
        for (int i = 0; p->choices[i]; i++) add(buf, n, &len, "%s%s", i ? "|" : "", p->choices[i]);
    } else {
        add(buf, n, &len, "%s", fv_param_type_name(p->type));
    }
    /* A float's default is printed as %g would: "0.667" for alpha's 2/3 written to the last bit. */
    if (p->def && p->type == FV_PARAM_FLOAT) add(buf, n, &len, " (%g", strtod(p->def, NULL));
    else if (p->def) add(buf, n, &len, " (%s", p->def);
    if (p->def_note) add(buf, n, &len, "%s%s", p->def ? ", " : " (", p->def_note);
    if (p->def || p->def_note) add(buf, n, &len, ")");
    if ((p->type == FV_PARAM_INT || p->type == FV_PARAM_FLOAT) && !p->choices)
        add(buf, n, &len, " in %c%.15g, %.15g%c", p->min_open ? '(' : '[', p->min, p->max, p->max_open ? ')' : ']');
    if (p->help) add(buf, n, &len, ": %s", p->help);
    return len;
}
