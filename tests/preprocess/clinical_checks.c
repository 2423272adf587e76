/* SPDX-License-Identifier: Apache-2.0 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "clinical_checks.h"

static const double DOWN[3] = {0, 0, -1}, FORWARD[3] = {1, 0, 0};

double clinical_segment_angle(const posture_api *api, const char *a, const char *b, const double dir[3])
{
    double pa[3], pb[3], d[3], n = 0, dot = 0, nd = 0;
    api->where(api->ctx, a, pa);
    api->where(api->ctx, b, pb);
    for (int k = 0; k < 3; k++) {
        d[k] = pb[k] - pa[k];
        n += d[k] * d[k];
        nd += dir[k] * dir[k];
        dot += d[k] * dir[k];
    }
    return acos(fmax(-1.0, fmin(1.0, dot / sqrt(n * nd)))) * 57.29577951308232;
}

static void check_below(const posture_api *api, const char *a, const char *b, const double dir[3],
                        double max_deg, const char *what)
{
    double deg = clinical_segment_angle(api, a, b, dir);
    printf("  %-40s %-10s -> %-8s %5.1f deg (limit %.0f)\n", what, a, b, deg, max_deg);
    assert_true(deg < max_deg);
}

static double height(const posture_api *api, const char *joint)
{
    double p[3];
    api->where(api->ctx, joint, p);
    return p[2];
}

void clinical_check_postures(const posture_api *api)
{
    static const char *side[2] = {"_r", "_l"};
    char sh[16], el[16], wr[16], hip[16], kn[16], an[16];
    for (int s = 0; s < 2; s++) {
        snprintf(sh, sizeof sh, "shoulder%s", side[s]);
        snprintf(el, sizeof el, "elbow%s", side[s]);
        snprintf(wr, sizeof wr, "wrist%s", side[s]);
        snprintf(hip, sizeof hip, "hip%s", side[s]);
        snprintf(kn, sizeof kn, "knee%s", side[s]);
        snprintf(an, sizeof an, "ankle%s", side[s]);

        /* The T-pose direction of the upper arm, for abduction 90. */
        api->rest(api->ctx);
        double pa[3], pb[3], tpose[3];
        api->where(api->ctx, sh, pa);
        api->where(api->ctx, el, pb);
        for (int k = 0; k < 3; k++)
            tpose[k] = pb[k] - pa[k];

        api->neutral(api->ctx);
        check_below(api, sh, el, DOWN, 5, "neutral: upper arm straight down");
        check_below(api, el, wr, DOWN, 5, "neutral: forearm straight down");
        check_below(api, hip, kn, DOWN, 5, "neutral: thigh straight down");
        check_below(api, kn, an, DOWN, 5, "neutral: shank straight down");

        api->set(api->ctx, sh, 0, 90, 0);
        check_below(api, sh, el, tpose, 10, "shoulder abduction 90: the T-pose");

        api->set(api->ctx, sh, 90, 0, 0);
        check_below(api, sh, el, FORWARD, 10, "shoulder flexion 90: forward, level");

        api->set(api->ctx, sh, 150, 0, 0);
        printf("  shoulder flexion 150: shoulder z %.3f, elbow z %.3f, wrist z %.3f, head z %.3f\n",
               height(api, sh), height(api, el), height(api, wr), height(api, "head"));
        assert_true(height(api, el) > height(api, sh));
        assert_true(height(api, wr) > height(api, sh));
        assert_true(height(api, wr) > height(api, "head"));

        api->neutral(api->ctx);
        api->set(api->ctx, hip, 90, 0, 0);
        api->set(api->ctx, kn, 90, 0, 0);
        check_below(api, hip, kn, FORWARD, 10, "seated (hip 90, knee 90): thigh forward");
        check_below(api, kn, an, DOWN, 10, "seated (hip 90, knee 90): shank vertical");
    }
}
