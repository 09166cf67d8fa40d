/* Embree's side of the ray-core comparison (scripts/embree-compare.sh builds and runs it):
 *   embree_compare DIR SCENE SET [REPS]
 * reads DIR/SCENE.tris and DIR/SCENE-SET.rays written by examples/embree_compare.rs, builds
 * one triangle geometry at RTC_BUILD_QUALITY_HIGH, and times single-threaded rtcIntersect1,
 * rtcOccluded1, rtcIntersect16 and rtcOccluded16 (16 consecutive rays per packet), REPS times
 * each, interleaved (this thread's CPU time, as the example measures); prints
 * `embree SCENE SET QUERY MRAYS HITS` per query and, against
 * DIR/SCENE-SET.hits (penumbra's closest hits), on how many rays the answers differ.
 * EMBREE_ROBUST=1 sets RTC_SCENE_FLAG_ROBUST (watertight-style edges; slower). */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static void *slurp(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) { fprintf(stderr, "embree_compare: cannot open %s\n", path); exit(1); }
    fseek(f, 0, SEEK_END);
    *len = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    void *p = malloc(*len);
    if (fread(p, 1, *len, f) != *len) { fprintf(stderr, "embree_compare: short read %s\n", path); exit(1); }
    fclose(f);
    return p;
}

static double now(void) {
    struct timespec t;
    /* This thread's CPU time, as examples/embree_compare.rs measures it. */
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static double wall(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: embree_compare DIR SCENE SET [REPS]\n"); return 2; }
    const char *dir = argv[1], *scene_name = argv[2], *set = argv[3];
    int reps = argc > 4 ? atoi(argv[4]) : 3;
    if (reps < 1 || reps > 64) reps = 3;
    char path[4096];
    size_t len;
    snprintf(path, sizeof path, "%s/%s.tris", dir, scene_name);
    uint8_t *tb = slurp(path, &len);
    uint32_t nt; memcpy(&nt, tb, 4);
    const float *tv = (const float *)(tb + 4);
    snprintf(path, sizeof path, "%s/%s-%s.rays", dir, scene_name, set);
    uint8_t *rb = slurp(path, &len);
    uint32_t nr; memcpy(&nr, rb, 4);
    const float *rv = (const float *)(rb + 4);
    snprintf(path, sizeof path, "%s/%s-%s.hits", dir, scene_name, set);
    uint32_t *ours = slurp(path, &len);

    RTCDevice dev = rtcNewDevice(NULL);
    RTCScene sc = rtcNewScene(dev);
    rtcSetSceneBuildQuality(sc, RTC_BUILD_QUALITY_HIGH);
    const char *robust = getenv("EMBREE_ROBUST");
    if (robust && robust[0] == '1') rtcSetSceneFlags(sc, RTC_SCENE_FLAG_ROBUST);
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
    float *v = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       3 * sizeof(float), 3 * (size_t)nt);
    unsigned *ix = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), nt);
    memcpy(v, tv, 9 * sizeof(float) * (size_t)nt);
    for (uint32_t i = 0; i < 3 * nt; i++) ix[i] = i;
    rtcCommitGeometry(geom);
    rtcAttachGeometry(sc, geom);
    rtcReleaseGeometry(geom);
    double t0 = wall();
    rtcCommitScene(sc);
    fprintf(stderr, "embree %s: %u triangles, build %.3f s, %u %s rays%s\n", scene_name, nt,
            wall() - t0, nr, set, robust && robust[0] == '1' ? " (robust)" : "");

    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    double secs[4][64];
    long hits[4] = {0};
    long hit_miss = 0, tie = 0, other = 0;
    for (int r = 0; r < reps; r++) {
        long h = 0;
        double s = now();
        for (uint32_t i = 0; i < nr; i++) {
            const float *q = rv + 7 * (size_t)i;
            struct RTCRayHit rh;
            rh.ray.org_x = q[0]; rh.ray.org_y = q[1]; rh.ray.org_z = q[2];
            rh.ray.dir_x = q[3]; rh.ray.dir_y = q[4]; rh.ray.dir_z = q[5];
            rh.ray.tnear = 0.0f; rh.ray.tfar = q[6]; rh.ray.time = 0.0f;
            rh.ray.mask = -1; rh.ray.id = 0; rh.ray.flags = 0;
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID; rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(sc, &ctx, &rh);
            if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) h++;
            if (r == 0) {
                uint32_t id = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.hit.primID : UINT32_MAX;
                float t;
                memcpy(&t, &ours[2 * (size_t)i + 1], 4);
                if ((id == UINT32_MAX) != (ours[2 * (size_t)i] == UINT32_MAX)) hit_miss++;
                else if (id != ours[2 * (size_t)i]) {
                    /* Another triangle at the same distance (a shared edge or coplanar
                     * overlap) is a tie, not a different answer. */
                    if (fabsf(rh.ray.tfar - t) <= 1e-5f * t) tie++; else other++;
                }
            }
        }
        secs[0][r] = now() - s; hits[0] = h;

        h = 0; s = now();
        for (uint32_t i = 0; i < nr; i++) {
            const float *q = rv + 7 * (size_t)i;
            struct RTCRay ray;
            ray.org_x = q[0]; ray.org_y = q[1]; ray.org_z = q[2];
            ray.dir_x = q[3]; ray.dir_y = q[4]; ray.dir_z = q[5];
            ray.tnear = 0.0f; ray.tfar = q[6]; ray.time = 0.0f;
            ray.mask = -1; ray.id = 0; ray.flags = 0;
            rtcOccluded1(sc, &ctx, &ray);
            h += ray.tfar < 0.0f;
        }
        secs[1][r] = now() - s; hits[1] = h;

        h = 0; s = now();
        for (uint32_t b = 0; b < nr; b += 16) {
            struct RTCRayHit16 rh __attribute__((aligned(64)));
            int valid[16] __attribute__((aligned(64)));
            for (int k = 0; k < 16; k++) {
                uint32_t i = b + k < nr ? b + k : b;
                const float *q = rv + 7 * (size_t)i;
                valid[k] = b + k < nr ? -1 : 0;
                rh.ray.org_x[k] = q[0]; rh.ray.org_y[k] = q[1]; rh.ray.org_z[k] = q[2];
                rh.ray.dir_x[k] = q[3]; rh.ray.dir_y[k] = q[4]; rh.ray.dir_z[k] = q[5];
                rh.ray.tnear[k] = 0.0f; rh.ray.tfar[k] = q[6]; rh.ray.time[k] = 0.0f;
                rh.ray.mask[k] = -1; rh.ray.id[k] = 0; rh.ray.flags[k] = 0;
                rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect16(valid, sc, &ctx, &rh);
            for (int k = 0; k < 16; k++) h += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        }
        secs[2][r] = now() - s; hits[2] = h;

        h = 0; s = now();
        for (uint32_t b = 0; b < nr; b += 16) {
            struct RTCRay16 ray __attribute__((aligned(64)));
            int valid[16] __attribute__((aligned(64)));
            for (int k = 0; k < 16; k++) {
                uint32_t i = b + k < nr ? b + k : b;
                const float *q = rv + 7 * (size_t)i;
                valid[k] = b + k < nr ? -1 : 0;
                ray.org_x[k] = q[0]; ray.org_y[k] = q[1]; ray.org_z[k] = q[2];
                ray.dir_x[k] = q[3]; ray.dir_y[k] = q[4]; ray.dir_z[k] = q[5];
                ray.tnear[k] = 0.0f; ray.tfar[k] = q[6]; ray.time[k] = 0.0f;
                ray.mask[k] = -1; ray.id[k] = 0; ray.flags[k] = 0;
            }
            rtcOccluded16(valid, sc, &ctx, &ray);
            for (int k = 0; k < 16; k++) h += valid[k] && ray.tfar[k] < 0.0f;
        }
        secs[3][r] = now() - s; hits[3] = h;
    }
    const char *names[4] = {"closest1", "any1", "closest16", "any16"};
    for (int k = 0; k < 4; k++) {
        qsort(secs[k], reps, sizeof(double), cmp);
        printf("embree %s %s %s %.3f %ld\n", scene_name, set, names[k],
               nr / secs[k][reps / 2] / 1e6, hits[k]);
    }
    printf("embree %s %s differences hit-vs-miss %ld, other-prim-same-t %ld, other-prim-other-t %ld\n",
           scene_name, set, hit_miss, tie, other);
    rtcReleaseScene(sc);
    rtcReleaseDevice(dev);
    free(tb); free(rb); free(ours);
    return 0;
}
