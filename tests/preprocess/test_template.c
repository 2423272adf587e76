/* SPDX-License-Identifier: Apache-2.0
 * Skeleton templates: every malformed input is refused with a message that
 * names the file, the line and what is wrong; the shipped template reads. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake_pipeline.h"
#include "template_json.h"

#define HEAD "{\"format\": \"pose-skeleton-template\", \"version\": 1, \"joints\": [\n"
#define ROOT "{\"name\": \"pelvis\", \"parent\": null, \"rule\": \"root\", \"bones\": [\"p\"]}"
/* The root and a knee, then a "couplings" array (its entries follow). */
#define KNEE HEAD ROOT ",\n{\"name\": \"knee\", \"parent\": \"pelvis\", \"rule\": \"hinge\", " \
             "\"bones\": [\"tibia\", \"fibula\"]}],\n\"couplings\": ["

typedef struct bad_case {
    const char *text;
    int status;
    const char *message; /* expected substring */
} bad_case;

static void test_rejects_malformed(void **state)
{
    (void)state;
    static const bad_case cases[] = {
        {"", POSE_ERR_FORMAT, "t.json: line 1 (offset 0): not valid JSON"},
        {"{\"format\": \"pose-skeleton-template\",\n \"version\": 1,\n \"joints\": [}", POSE_ERR_FORMAT,
         "t.json: line 3"},
        {"[]", POSE_ERR_FORMAT, "top level must be an object"},
        {"{\"format\": \"other\", \"version\": 1}", POSE_ERR_FORMAT, "'format' must be"},
        {"{\"format\": \"pose-skeleton-template\", \"version\": 2}", POSE_ERR_VERSION, "'version' must be 1"},
        {HEAD "]}", POSE_ERR_FORMAT, "'joints' must be a non-empty array"},
        {"{\"format\": \"pose-skeleton-template\", \"version\": 1, \"jionts\": []}", POSE_ERR_FORMAT,
         "unknown top-level key 'jionts'"},
        {HEAD "{\"parent\": null}]}", POSE_ERR_FORMAT, "joints[0]: 'name' must be"},
        {HEAD "{\"name\": \"pelvis\", \"rule\": \"root\"}]}", POSE_ERR_FORMAT,
         "t.json:2: joint 'pelvis': missing or empty 'bones'"},
        {HEAD "{\"name\": \"pelvis\", \"bones\": [\"p\"]}]}", POSE_ERR_FORMAT, "joint 'pelvis': missing 'rule'"},
        {HEAD "{\"name\": \"pelvis\", \"rule\": \"ballz\", \"bones\": [\"p\"]}]}", POSE_ERR_FORMAT,
         "'rule' must be one of root, ball, hinge, spine, fixed"},
        {HEAD ROOT ",\n{\"name\": \"knee\", \"parent\": \"hip\", \"rule\": \"hinge\", \"bones\": [\"t\"]}]}",
         POSE_ERR_INVALID_DATA, "t.json:3: joint 'knee': parent 'hip' is not a joint listed before this one"},
        {HEAD ROOT ",\n{\"name\": \"pelvis\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"]}]}",
         POSE_ERR_INVALID_DATA, "joint 'pelvis': name used twice"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"p\"]}]}",
         POSE_ERR_INVALID_DATA, "joint 'hip': bone 'p' is already in joint 'pelvis'"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\", \"f\"]}]}",
         POSE_ERR_INVALID_DATA, "'bones' lists 'f' twice"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"root\", \"bones\": [\"f\"]}]}",
         POSE_ERR_INVALID_DATA, "rule 'root' is only for a joint without parent"},
        {HEAD "{\"name\": \"pelvis\", \"parent\": null, \"rule\": \"ball\", \"bones\": [\"p\"]}]}",
         POSE_ERR_INVALID_DATA, "a joint without parent must have rule 'root'"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"fixed\", \"bones\": [\"f\"]}]}",
         POSE_ERR_FORMAT, "rule 'fixed' needs 'at'"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"contact\": [\"g\"]}]}",
         POSE_ERR_INVALID_DATA, "'contact' names 'g', which is not in 'bones'"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"parent_contact\": [\"x\"]}]}",
         POSE_ERR_INVALID_DATA, "'parent_contact' names 'x', which is not in parent 'pelvis' bones"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"limits\": {\"y\": [10, -10]}}]}",
         POSE_ERR_FORMAT, "'limits.y' must be [min, max]"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"limits\": {\"order\": \"XXY\"}}]}",
         POSE_ERR_FORMAT, "'limits.order' must be one of"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"axis\": [0, 0, 0]}]}",
         POSE_ERR_FORMAT, "'axis' must be a non-zero [x, y, z]"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"contact_mm\": -1}]}",
         POSE_ERR_FORMAT, "'contact_mm' must be a number in (0, 100]"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"colour\": 1}]}",
         POSE_ERR_FORMAT, "t.json:3: joint 'hip': unknown key 'colour'"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"bones\": [\"g\"]}]}",
         POSE_ERR_FORMAT, "t.json:3: joint 'hip': key 'bones' appears twice"},
        /* "clinical": the neutral posture and clinical axes. */
        {HEAD "{\"name\": \"pelvis\", \"parent\": null, \"rule\": \"root\", \"bones\": [\"p\"], "
              "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 1}}]}",
         POSE_ERR_INVALID_DATA, "t.json:2: joint 'pelvis': the root has no clinical angles"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": [0, 1, 0]}]}",
         POSE_ERR_FORMAT, "t.json:3: joint 'hip': 'clinical' must be an object"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"rotation\": 1}}]}",
         POSE_ERR_FORMAT, "joint 'hip': 'clinical' needs 'flexion', 'abduction' and 'rotation'"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 0, 0], \"abduction\": [1, 0, 0], \"rotation\": 1}}]}",
         POSE_ERR_FORMAT, "joint 'hip': 'clinical.flexion' must be a non-zero [x, y, z]"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"neutral\": \"down\", \"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], "
                   "\"rotation\": 1}}]}",
         POSE_ERR_FORMAT, "joint 'hip': 'clinical.neutral' must be a non-zero [x, y, z]"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 0}}]}",
         POSE_ERR_FORMAT, "t.json:3: joint 'hip': 'clinical.rotation' must be 1"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [0, 1, 0.2], \"rotation\": 1}}]}",
         POSE_ERR_INVALID_DATA, "joint 'hip': 'clinical.flexion' and 'clinical.abduction' are 11 degrees apart"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"neutral\": [1, 0, 0], \"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], "
                   "\"rotation\": 1}}]}",
         POSE_ERR_INVALID_DATA, "'clinical.neutral' and 'clinical.abduction' are 0 degrees apart"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 1, "
                   "\"names\": [\"flexion\", \"abduction\"]}}]}",
         POSE_ERR_FORMAT, "joint 'hip': 'clinical.names' must be 3 names"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 1, "
                   "\"names\": [\"flexion\", \"\", \"rotation\"]}}]}",
         POSE_ERR_FORMAT, "joint 'hip': 'clinical.names' entry 1 must be a string of 1..31 bytes"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 1, "
                   "\"limits\": {\"flexion\": [120, -30]}}}]}",
         POSE_ERR_FORMAT, "joint 'hip': 'clinical.limits.flexion' must be [min, max] degrees"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 1, "
                   "\"limits\": {\"y\": [0, 10]}}}]}",
         POSE_ERR_FORMAT, "unknown key 'clinical.limits.y' (expected flexion, abduction, rotation)"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 1, "
                   "\"axis\": [0, 1, 0]}}]}",
         POSE_ERR_FORMAT, "t.json:3: joint 'hip': unknown key 'clinical.axis'"},
        {HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"ball\", \"bones\": [\"f\"], "
                   "\"clinical\": {\"flexion\": [0, 1, 0], \"abduction\": [1, 0, 0], \"rotation\": 1, "
                   "\"rotation\": -1}}]}",
         POSE_ERR_FORMAT, "joint 'hip': key 'clinical.rotation' appears twice"},
        {KNEE "{\"bone\": \"femur\", \"reach_mm\": 10}]}", POSE_ERR_INVALID_DATA,
         "t.json: couplings[0]: bone 'femur' is in no joint's 'bones'"},
        {KNEE "{\"joint\": \"knee\", \"reach_mm\": 10}, {\"joint\": \"hip\", \"reach_mm\": 5}]}",
         POSE_ERR_INVALID_DATA, "t.json: couplings[1]: joint 'hip' is not in 'joints'"},
        {KNEE "{\"bone\": \"tibia\", \"joint\": \"knee\", \"reach_mm\": 10}]}", POSE_ERR_FORMAT,
         "couplings[0]: give either 'bone' or 'joint', not both"},
        {KNEE "{\"bone\": \"tibia\"}]}", POSE_ERR_FORMAT,
         "couplings[0]: needs 'bone' or 'joint', and 'reach_mm'"},
        {KNEE "{\"bone\": \"tibia\", \"reach_mm\": 0}]}", POSE_ERR_FORMAT,
         "couplings[0]: 'reach_mm' must be a number in (0, 100]"},
        {KNEE "{\"bone\": \"tibia\", \"reach_mm\": 120}]}", POSE_ERR_FORMAT,
         "couplings[0]: 'reach_mm' must be a number in (0, 100]"},
        {KNEE "{\"bone\": \"tibia\", \"reach_mm\": 8, \"stiffness\": -3}]}", POSE_ERR_FORMAT,
         "couplings[0]: 'stiffness' must be a number in (0, 1e6]"},
        {KNEE "{\"bone\": \"tibia\", \"reach_mm\": 8, \"soft\": \"skin\"}]}", POSE_ERR_FORMAT,
         "couplings[0]: unknown key 'soft'"},
        {KNEE "{\"bone\": \"tibia\", \"reach_mm\": 8, \"reach_mm\": 9}]}", POSE_ERR_FORMAT,
         "couplings[0]: key 'reach_mm' appears twice"},
        {KNEE "{\"bone\": \"tibia\", \"reach_mm\": 8}, {\"bone\": \"tibia\", \"reach_mm\": 3}]}",
         POSE_ERR_INVALID_DATA, "couplings[1]: the same bone 'tibia' as couplings[0]"},
        {KNEE "7]}", POSE_ERR_FORMAT, "couplings[0] must be an object"},
        {KNEE "{\"tissue\": \"fascia\", \"reach_mm\": 2}]}", POSE_ERR_FORMAT,
         "couplings[0]: a soft-soft coupling needs 'tissue', 'to' and 'reach_mm'"},
        {KNEE "{\"tissue\": \"fascia\", \"to\": \"muscle\", \"bone\": \"tibia\", \"reach_mm\": 2}]}",
         POSE_ERR_FORMAT, "couplings[0]: a soft-soft coupling needs"},
        {KNEE "{\"tissue\": \"fascia\", \"to\": \"fascia\", \"reach_mm\": 2}]}",
         POSE_ERR_INVALID_DATA, "couplings[0]: 'tissue' and 'to' are both 'fascia'"},
        {KNEE "{\"tissue\": \"fascia\", \"to\": \"muscle\", \"reach_mm\": 12}]}", POSE_ERR_FORMAT,
         "couplings[0]: a soft-soft 'reach_mm' must be in (0, 10]"},
        {KNEE "{\"tissue\": \"fascia\", \"to\": 3, \"reach_mm\": 2}]}", POSE_ERR_FORMAT,
         "couplings[0]: 'to' must be a tissue name of 1..63 bytes"},
        {KNEE "{\"tissue\": \"a\", \"to\": \"b\", \"reach_mm\": 2},\n"
              "{\"to\": \"b\", \"tissue\": \"a\", \"reach_mm\": 1}]}",
         POSE_ERR_INVALID_DATA, "couplings[1]: the same tissues 'a' and 'b' as couplings[0]"},
        {HEAD ROOT "], \"couplings\": {}}", POSE_ERR_FORMAT, "'couplings' must be an array"},
        {HEAD "{\"name\": \"0123456789012345678901234567890123456789012345678901234567890123\", "
              "\"rule\": \"root\", \"bones\": [\"p\"]}]}",
         POSE_ERR_FORMAT, "'name' must be a string of 1..63 bytes"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        pp_template t;
        char err[512];
        int rc = pp_template_parse(cases[i].text, strlen(cases[i].text), "t.json", &t, err, sizeof err);
        if (rc != cases[i].status || !strstr(err, cases[i].message))
            fail_msg("case %zu: status %d, message '%s'; expected %d and '%s'", i, rc, err,
                     cases[i].status, cases[i].message);
        assert_int_equal(t.joint_count, 0);
        assert_null(t.joints);
        assert_int_equal(t.coupling_count, 0);
        assert_null(t.couplings);
    }
}

/* "couplings": a bone or a joint's whole segment, reach, stiffness (default 100). */
static void test_reads_couplings(void **state)
{
    (void)state;
    const char *text = KNEE "{\"bone\": \"tibia\", \"reach_mm\": 12.5, \"comment\": \"shin\"},\n"
                            "{\"joint\": \"knee\", \"reach_mm\": 3, \"stiffness\": 20},\n"
                            "{\"bone\": \"p\", \"reach_mm\": 100, \"stiffness\": 1e6}]}";
    pp_template t;
    char err[512];
    if (pp_template_parse(text, strlen(text), "t.json", &t, err, sizeof err) != POSE_OK)
        fail_msg("%s", err);
    assert_int_equal(t.coupling_count, 3);
    assert_string_equal(t.couplings[0].bone, "tibia");
    assert_int_equal(t.couplings[0].joint, 1);
    assert_true(t.couplings[0].reach_mm == 12.5f && t.couplings[0].stiffness == 100.0f);
    assert_string_equal(t.couplings[1].bone, ""); /* the whole segment */
    assert_int_equal(t.couplings[1].joint, 1);
    assert_true(t.couplings[1].reach_mm == 3.0f && t.couplings[1].stiffness == 20.0f);
    assert_int_equal(t.couplings[2].joint, 0);
    assert_true(t.couplings[2].stiffness == 1e6f);
    pp_template_free(&t);
    /* the soft-soft form: two tissues, beside couplings to bones */
    const char *soft = KNEE "{\"bone\": \"tibia\", \"reach_mm\": 12.5},\n"
                            "{\"tissue\": \"fascia\", \"to\": \"muscle\", \"reach_mm\": 2, "
                            "\"stiffness\": 50}]}";
    if (pp_template_parse(soft, strlen(soft), "t.json", &t, err, sizeof err) != POSE_OK)
        fail_msg("%s", err);
    assert_int_equal(t.coupling_count, 2);
    assert_string_equal(t.couplings[0].tissue, "");
    assert_int_equal(t.couplings[1].joint, -1);
    assert_string_equal(t.couplings[1].tissue, "fascia");
    assert_string_equal(t.couplings[1].to, "muscle");
    assert_true(t.couplings[1].reach_mm == 2.0f && t.couplings[1].stiffness == 50.0f);
    pp_template_free(&t);
    assert_int_equal(t.coupling_count, 0);
    /* an empty array: no couplings */
    const char *none = KNEE "]}";
    assert_int_equal(pp_template_parse(none, strlen(none), "t.json", &t, err, sizeof err), POSE_OK);
    assert_int_equal(t.coupling_count, 0);
    pp_template_free(&t);
}

/* pp_bake_soft_couplings on two cubes of 6 tets, 1 cm, meshed apart: B's
 * beside A at x = 1 cm (its face nodes on A's), then 0.5 mm beyond it. A's
 * free face nodes within reach of B's tets are tied to their nearest point
 * (one corner of weight 1 when they touch), the others not; a tissue the
 * bake does not have is named. */
static void test_resolves_soft_couplings(void **state)
{
    (void)state;
    static const int path[6][2] = {{1, 3}, {1, 5}, {2, 3}, {2, 6}, {4, 5}, {4, 6}};
    float pos[16 * 3];
    uint32_t tets[12 * 4], emb[12];
    uint16_t labels[12] = {0};
    for (int gap = 0; gap < 2; gap++) {
        for (int c = 0; c < 16; c++) {
            const int cube = c / 8, k = c % 8;
            pos[3 * c] = 0.01f * (float)(cube + (k & 1)) + (cube && gap ? 5e-4f : 0.0f);
            pos[3 * c + 1] = 0.01f * (float)((k >> 1) & 1);
            pos[3 * c + 2] = 0.01f * (float)((k >> 2) & 1);
        }
        for (int t = 0; t < 12; t++) {
            const uint32_t o = t < 6 ? 0 : 8;
            const uint32_t v[4] = {o, o + (uint32_t)path[t % 6][0], o + (uint32_t)path[t % 6][1],
                                   o + 7};
            memcpy(tets + 4 * t, v, sizeof v);
            emb[t] = (uint32_t)t;
        }
        const pp_tetmesh mesh = {16, pos, 12, tets, labels};
        /* tissue a: a vertex in each of A's tets; b: in each of B's */
        const pose_tissue_desc tissues[2] = {{.name = "a", .vertex_count = 6, .tet = emb},
                                             {.name = "b", .vertex_count = 6, .tet = emb + 6}};
        const char *text = KNEE "{\"tissue\": \"a\", \"to\": \"b\", \"reach_mm\": 1}]}";
        pp_template t;
        char err[512];
        if (pp_template_parse(text, strlen(text), "t.json", &t, err, sizeof err) != POSE_OK)
            fail_msg("%s", err);
        pose_fem_soft_coupling *c = NULL;
        size_t n = 0;
        assert_int_equal(pp_bake_soft_couplings(&t, tissues, 2, &mesh, &c, &n, err, sizeof err),
                         POSE_OK);
        assert_int_equal(n, 4); /* A's face x = 1 cm: corners 1, 3, 5, 7 */
        for (size_t i = 0; i < n; i++) {
            assert_true(c[i].node % 2 == 1 && c[i].node < 8);
            double p[3] = {0, 0, 0}, d2 = 0.0, sum = 0.0;
            for (int k = 0; k < 4; k++) {
                sum += c[i].weight[k];
                for (int a = 0; a < 3; a++)
                    p[a] += c[i].weight[k] * pos[3 * c[i].other[k] + (uint32_t)a];
            }
            for (int a = 0; a < 3; a++)
                d2 += pow(p[a] - pos[3 * c[i].node + (uint32_t)a], 2);
            assert_true(fabs(sum - 1.0) < 1e-6);
            /* touching: B's own corner; apart: its face, 0.5 mm away */
            assert_true(fabs(sqrt(d2) - (gap ? 5e-4 : 0.0)) < 1e-6);
            assert_true(c[i].stiffness == 100.0f);
        }
        free(c);
        pp_template_free(&t);
        const char *far = KNEE "{\"tissue\": \"a\", \"to\": \"b\", \"reach_mm\": 0.4}]}";
        assert_int_equal(pp_template_parse(far, strlen(far), "t.json", &t, err, sizeof err), POSE_OK);
        assert_int_equal(pp_bake_soft_couplings(&t, tissues, 2, &mesh, &c, &n, err, sizeof err),
                         POSE_OK);
        assert_int_equal(n, gap ? 0 : 4);
        free(c);
        pp_template_free(&t);
        const char *missing = KNEE "{\"tissue\": \"a\", \"to\": \"c\", \"reach_mm\": 1}]}";
        assert_int_equal(pp_template_parse(missing, strlen(missing), "t.json", &t, err, sizeof err),
                         POSE_OK);
        assert_int_equal(pp_bake_soft_couplings(&t, tissues, 2, &mesh, &c, &n, err, sizeof err),
                         POSE_ERR_INVALID_ARGUMENT);
        assert_non_null(strstr(err, "couplings[0] names tissue 'c', but the bake has no such mesh"));
        assert_null(c);
        pp_template_free(&t);
    }
}

static void test_missing_file(void **state)
{
    (void)state;
    pp_template t;
    char err[512];
    assert_int_equal(pp_template_load("/nonexistent/full_body.json", &t, err, sizeof err), POSE_ERR_IO);
    assert_non_null(strstr(err, "/nonexistent/full_body.json: cannot open"));
}

static void test_reads_minimal(void **state)
{
    (void)state;
    const char *text = HEAD ROOT ",\n{\"name\": \"hip\", \"parent\": \"pelvis\", \"rule\": \"hinge\", "
                            "\"bones\": [\"f\", \"pat\"], \"contact\": [\"f\"], \"fit\": \"both\", "
                            "\"contact_mm\": 7.5, \"grow_mm\": 30, \"axis\": [0, 2, 0], \"up\": [0, 0, -1], "
                            "\"limits\": {\"order\": \"ZXY\", \"y\": [-120, 30]}}]}";
    pp_template t;
    char err[512];
    assert_int_equal(pp_template_parse(text, strlen(text), "t.json", &t, err, sizeof err), POSE_OK);
    assert_int_equal(t.joint_count, 2);
    const pp_template_joint *j = &t.joints[1];
    assert_string_equal(j->name, "hip");
    assert_int_equal(j->parent, 0);
    assert_int_equal(j->rule, PP_FIT_HINGE);
    assert_int_equal(j->side, PP_SIDE_BOTH);
    assert_int_equal(j->bone_count, 2);
    assert_string_equal(j->bones[1], "pat");
    assert_int_equal(j->contact_count, 1);
    assert_true(j->contact_mm == 7.5f && j->grow_mm == 30.0f);
    assert_true(j->axis[1] == 1.0f && j->up[2] == -1.0f); /* normalized */
    assert_int_equal(j->limit_flags, POSE_LIMIT_Y);
    assert_int_equal(j->limit_order, POSE_EULER_ZXY);
    assert_true(j->limit_min_deg[1] == -120.0f && j->limit_max_deg[1] == 30.0f);
    assert_int_equal(pp_template_joint_of_bone(&t, "pat"), 1);
    assert_int_equal(pp_template_joint_of_bone(&t, "skin"), -1);
    assert_int_equal(t.joints[0].contact_mm, 4.0f); /* the default */
    assert_false(j->clinical.defined);
    pp_template_free(&t);
    pp_template_free(&t); /* harmless twice */
}

static void test_reads_clinical(void **state)
{
    (void)state;
    const char *text = HEAD ROOT ",\n{\"name\": \"shoulder_r\", \"parent\": \"pelvis\", \"rule\": \"ball\", "
                            "\"bones\": [\"h\"], \"clinical\": {\"neutral\": [0, 0, -2], \"flexion\": [0, -1, 0], "
                            "\"abduction\": [-1, 0, 0.1], \"rotation\": -1, \"comment\": \"glenohumeral\", "
                            "\"names\": [\"flexion\", \"abduction\", \"internal_rotation\"], "
                            "\"limits\": {\"flexion\": [-60, 180], \"rotation\": [-90, 70]}}}]}";
    pp_template t;
    char err[512];
    assert_int_equal(pp_template_parse(text, strlen(text), "t.json", &t, err, sizeof err), POSE_OK);
    const pp_template_clinical *k = &t.joints[1].clinical;
    assert_true(k->defined && k->has_neutral);
    assert_true(k->neutral[0] == 0.0f && k->neutral[2] == -1.0f); /* normalized */
    assert_true(k->flexion[1] == -1.0f);
    assert_true(fabsf(k->abduction[0] + 0.995037f) < 1e-6f && fabsf(k->abduction[2] - 0.0995037f) < 1e-6f);
    assert_int_equal(k->rotation_sign, -1);
    assert_string_equal(k->names[2], "internal_rotation");
    assert_int_equal(k->limit_flags, POSE_LIMIT_X | POSE_LIMIT_Z);
    assert_true(k->limit_min_deg[0] == -60.0f && k->limit_max_deg[0] == 180.0f);
    assert_true(k->limit_min_deg[2] == -90.0f && k->limit_max_deg[2] == 70.0f);
    assert_false(t.joints[0].clinical.defined);
    pp_template_free(&t);
}

/* The shipped full-body template: the names other components map onto. */
static void test_full_body_template(void **state)
{
    (void)state;
    const char *data = getenv("POSE_DATA_DIR");
    assert_non_null(data);
    char path[1024];
    snprintf(path, sizeof path, "%s/../preprocess/templates/full_body.json", data);
    pp_template t;
    char err[512];
    assert_int_equal(pp_template_load(path, &t, err, sizeof err), POSE_OK);
    static const char *names[] = {"pelvis", "lumbar", "thorax", "neck", "head",
                                  "clavicle_r", "shoulder_r", "elbow_r", "wrist_r",
                                  "clavicle_l", "shoulder_l", "elbow_l", "wrist_l",
                                  "hip_r", "knee_r", "ankle_r", "hip_l", "knee_l", "ankle_l"};
    assert_int_equal(t.joint_count, sizeof names / sizeof names[0]);
    for (size_t i = 0; i < t.joint_count; i++)
        assert_int_equal(pp_template_find_joint(&t, names[i]), (int)i);
    assert_int_equal(t.joints[pp_template_find_joint(&t, "knee_r")].parent,
                     pp_template_find_joint(&t, "hip_r"));
    assert_int_equal(pp_template_joint_of_bone(&t, "r_tibia"), pp_template_find_joint(&t, "knee_r"));
    assert_int_equal(pp_template_joint_of_bone(&t, "l_3distph"), pp_template_find_joint(&t, "wrist_l"));
    /* 102 bones, each in exactly one segment. */
    size_t bones = 0;
    for (size_t i = 0; i < t.joint_count; i++)
        bones += t.joints[i].bone_count;
    assert_int_equal(bones, 102);
    /* Clinical data on every joint but the root, AAOS ranges where AAOS has
     * them: shoulder flexion 180, extension 60; knee flexion 0..135. */
    for (size_t i = 0; i < t.joint_count; i++)
        assert_int_equal(t.joints[i].clinical.defined, t.joints[i].parent >= 0);
    const pp_template_clinical *sh = &t.joints[pp_template_find_joint(&t, "shoulder_l")].clinical;
    assert_true(sh->limit_min_deg[0] == -60.0f && sh->limit_max_deg[0] == 180.0f);
    const pp_template_clinical *kn = &t.joints[pp_template_find_joint(&t, "knee_r")].clinical;
    assert_true(kn->limit_min_deg[0] == 0.0f && kn->limit_max_deg[0] == 135.0f);
    pp_template_free(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rejects_malformed),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_reads_minimal),
        cmocka_unit_test(test_reads_clinical),
        cmocka_unit_test(test_reads_couplings),
        cmocka_unit_test(test_resolves_soft_couplings),
        cmocka_unit_test(test_full_body_template),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
