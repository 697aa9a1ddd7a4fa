/* fovea — typed JSON of a method's parameters. The bag holds text (fovea/params.h); the type of
 * each key is the one the method's registry entry declares in its help ("key=int (16): ..."), so
 * "16" for spp is written as the number 16 and "on" for a bool as true. A key the help does not
 * declare (device, or a method without help) is a number when the whole value reads as a finite
 * number, else text. A value its declared type cannot read stays text: the report shows what was
 * given, and fv_technique_create would have refused it anyway.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "drive/params_json.h"
#include "fovea/technique.h"

typedef enum ptype { P_UNKNOWN, P_NUMBER, P_BOOL, P_TEXT } ptype;

/* The declared type of `key` in a help text of lines "key=type (default): meaning". */
static ptype declared_type(const char *help, const char *key)
{
    size_t klen = strlen(key);
    for (const char *line = help; line && *line;) {
        if (strncmp(line, key, klen) == 0 && line[klen] == '=') {
            const char *t = line + klen + 1;
            size_t tlen = strcspn(t, " \n");
            if ((tlen == 3 && strncmp(t, "int", 3) == 0) || (tlen == 5 && strncmp(t, "float", 5) == 0)) return P_NUMBER;
            if (tlen == 4 && strncmp(t, "bool", 4) == 0) return P_BOOL;
            return P_TEXT;
        }
        const char *nl = strchr(line, '\n');
        line = nl ? nl + 1 : NULL;
    }
    return P_UNKNOWN;
}

static bool read_number(const char *s, double *out)
{
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v)) return false;
    *out = v;
    return true;
}

/* The spellings fv_params_bool accepts. */
static bool read_bool(const char *s, bool *out)
{
    static const char *const yes[] = {"1", "true", "yes", "on"}, *const no[] = {"0", "false", "no", "off"};
    for (int i = 0; i < 4; i++) {
        if (strcasecmp(s, yes[i]) == 0) return *out = true, true;
        if (strcasecmp(s, no[i]) == 0) return *out = false, true;
    }
    return false;
}

cJSON *fv_params_typed_json(const char *method, const fv_params *params)
{
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    int ti = method ? fv_technique_index(method) : -1;
    const char *help = ti >= 0 ? fv_technique_params_help(ti) : NULL;
    for (int i = 0; i < fv_params_count(params); i++) {
        const char *k = fv_params_key(params, i), *v = fv_params_value(params, i);
        ptype t = declared_type(help, k);
        double d;
        bool b;
        cJSON *item;
        if ((t == P_NUMBER || t == P_UNKNOWN) && read_number(v, &d)) item = cJSON_CreateNumber(d);
        else if (t == P_BOOL && read_bool(v, &b)) item = cJSON_CreateBool(b);
        else item = cJSON_CreateString(v);
        if (!item || !cJSON_AddItemToObject(o, k, item)) {
            cJSON_Delete(item);
            cJSON_Delete(o);
            return NULL;
        }
    }
    return o;
}
