/*
 * The coordinate reference system of a LAS scan, carried into glTF's asset extras (issue 29):
 * glTF has no CRS of its own, so a GIS that reads the GLB needs the source's words. ASPRS LAS 1.4
 * (R15) 2.5 keeps the CRS in VLRs of user "LASF_Projection": record 2112 the OGC WKT (a NUL-
 * terminated string), or the GeoTIFF keys: 34735 GeoKeyDirectoryTag (16-bit words: a 4-word
 * header whose last word is the key count, then per key id, tag location, count, value), 34736
 * GeoDoubleParamsTag and 34737 GeoAsciiParamsTag (GeoTIFF 1.0 2.4). The keys are kept whole;
 * the EPSG codes of the projected (3072), geographic (2048) and vertical (4096) system are named.
 */
#include <stdio.h>
#include <string.h>

#include "export/internal.h"
#include "util/banned.h"

static const asp_las_vlr *find(const asp_las_meta *las, uint16_t record)
{
    for (size_t i = 0; i < las->vlr_count; i++)
        if (las->vlrs[i].record_id == record && strcmp(las->vlrs[i].user_id, "LASF_Projection") == 0)
            return &las->vlrs[i];
    return NULL;
}

static unsigned word(const uint8_t *p, size_t i)
{
    return (unsigned)p[2 * i] | (unsigned)p[2 * i + 1] << 8; // LAS is little-endian
}

/* The text of a VLR up to its first NUL (a record need not end in one), as a cJSON string. */
static cJSON *text_of(const asp_las_vlr *v)
{
    size_t n = 0;
    while (n < v->size && v->data[n])
        n++;
    char *s = asp_alloc(NULL, n + 1);
    if (!s)
        return NULL;
    memcpy(s, v->data, n);
    s[n] = 0;
    cJSON *j = cJSON_CreateString(s);
    asp_free(NULL, s);
    return j;
}

static void add_geokeys(cJSON *crs, const asp_las_vlr *dir, const asp_las_meta *las)
{
    size_t words = dir->size / 2;
    if (words < 4)
        return;
    size_t keys = word(dir->data, 3);
    if (4 + 4 * keys > words)
        keys = (words - 4) / 4; // a short directory: the keys it holds
    cJSON *all = cJSON_AddArrayToObject(crs, "geoKeys");
    for (size_t i = 0; i < 4 + 4 * keys; i++)
        cJSON_AddItemToArray(all, cJSON_CreateNumber(word(dir->data, i)));
    static const struct {
        unsigned id;
        const char *name;
    } named[] = {{3072, "epsg"}, {2048, "epsgGeographic"}, {4096, "epsgVertical"}};
    for (size_t k = 0; k < keys; k++) {
        const uint8_t *e = dir->data + 8 + 8 * k;
        unsigned id = word(e, 0), location = word(e, 1), value = word(e, 3);
        for (size_t n = 0; n < sizeof named / sizeof named[0]; n++)
            // an inline value (location 0); 32767 is "user-defined", 0 "undefined"
            if (id == named[n].id && location == 0 && value > 0 && value < 32767)
                cJSON_AddNumberToObject(crs, named[n].name, value);
    }
    const asp_las_vlr *dbl = find(las, 34736), *ascii = find(las, 34737);
    if (dbl && dbl->size >= 8) {
        cJSON *d = cJSON_AddArrayToObject(crs, "geoDoubles");
        for (size_t i = 0; i + 8 <= dbl->size; i += 8) {
            double x;
            memcpy(&x, dbl->data + i, 8); // little-endian doubles (the library is little-endian only)
            cJSON_AddItemToArray(d, cJSON_CreateNumber(x));
        }
    }
    if (ascii)
        cJSON_AddItemToObject(crs, "geoAscii", text_of(ascii));
}

cJSON *asp__gltf_crs(const asp_las_meta *las)
{
    if (!las)
        return NULL;
    const asp_las_vlr *wkt = find(las, 2112), *keys = find(las, 34735);
    if (!wkt && !keys)
        return NULL;
    cJSON *crs = cJSON_CreateObject();
    if (!crs)
        return NULL;
    cJSON_AddStringToObject(crs, "from", "LAS LASF_Projection VLRs");
    if (wkt)
        cJSON_AddItemToObject(crs, "wkt", text_of(wkt));
    if (keys)
        add_geokeys(crs, keys, las);
    return crs;
}
