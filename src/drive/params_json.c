/* fovea — typed JSON of a method's parameters. The bag holds text (fovea/params.h); the type of
 * each key is the one the method's parameter table declares (fovea/technique.h, fv_param_info), so
 * "16" for spp is written as the number 16 and "on" for a bool as true. A key the table does not
 * declare (device, or an unknown method) is a number when the whole value reads as a finite
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

/* The declared type of `key` for method i. */
static ptype declared_type(int i, const char *key)
{
    const fv_param_info *p = fv_technique_param_find(i, key);
    if (!p) return P_UNKNOWN;
    switch (p->type) {
    case FV_PARAM_INT:
    case FV_PARAM_FLOAT: return P_NUMBER;
    case FV_PARAM_BOOL: return P_BOOL;
    case FV_PARAM_CHOICE:
    case FV_PARAM_STRING: break;
    }
    return P_TEXT;
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
    for (int i = 0; i < fv_params_count(params); i++) {
        const char *k = fv_params_key(params, i), *v = fv_params_value(params, i);
        ptype t = declared_type(ti, k);
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
