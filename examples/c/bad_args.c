/* Every entry point of msp.h, called with bad arguments, returns a status (or
 * the documented NaN / fault), never crashes: null pointers, buffers too small,
 * NaN and out-of-range parameters, dead times beyond the buffer, a handle of
 * the other precision and a buffer that is not a controller (every call checks
 * the tag, msp_update included: NaN out), finite measurements at the float
 * range's end (never a latched NaN). Then the good calls work, on a buffer at
 * an odd address. Exit status 0 when all hold. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "msp.h"

static int failures = 0;

#define EXPECT(cond)                                                   \
    do {                                                               \
        if (!(cond)) {                                                 \
            printf("FAIL line %d: %s\n", __LINE__, #cond);             \
            failures++;                                                \
        }                                                              \
    } while (0)

static unsigned char memory[1 << 16];
static unsigned char adapt_memory[1 << 15];
static unsigned char estimator_memory[1 << 14];

/* The adaptive controller `ad` on e^-1s/(4s+1) sampled at 0.1 s, whose lag
   doubles at sample 1500, for `samples` samples, the set point alternating
   every 300: the largest error at the end of a half period after sample
   6000. With `designs` not null, `msp_adaptive_design` is called after
   each update (as a background task would) and its designs counted. */
static float lag_doubles(msp_adaptive *ad, int samples, int *designs) {
    const float a = expf(-0.1f / 4.0f), a2 = expf(-0.1f / 8.0f);
    float y = 0.0f, line[10] = {0}, worst = 0.0f;
    for (int k = 0; k < samples; k++) {
        float r = (k / 300) % 2 == 0 ? 1.0f : 0.0f;
        float u = msp_adaptive_update(ad, r, y);
        int built = 0;
        if (designs != NULL && msp_adaptive_design(ad, &built) == MSP_OK) {
            *designs += built;
        }
        float late = line[k % 10];
        line[k % 10] = u;
        float p = k < 1500 ? a : a2;
        y = p * y + (1.0f - p) * late;
        if (k > 6000 && k % 300 == 299 && fabsf(y - r) > worst) {
            worst = fabsf(y - r);
        }
    }
    return worst;
}

/* Runs `relay` on the plant x[k+1] = a x[k] + b v[k], v the relay's output
   `delay` (at most 200) samples earlier, until it ends or 200 000 samples
   pass; its state, and its result in `rr`. */
static msp_relay_state relay_on(msp_relay *relay, float a, float b, int delay,
                                msp_relay_result *rr) {
    static float line[200];
    int head = 0;
    float x = 0.0f;
    msp_relay_state st = MSP_RELAY_RUNNING;
    for (int i = 0; i < delay; i++) {
        line[i] = 0.0f;
    }
    for (int i = 0; i < 200000 && st == MSP_RELAY_RUNNING; i++) {
        float u = msp_relay_update(relay, x);
        float v = line[head];
        line[head] = u;
        head = (head + 1) % delay;
        x = a * x + b * v;
        EXPECT(msp_relay_poll(relay, &st, rr) == MSP_OK);
    }
    return st;
}

int main(void) {
    msp_status s;
    msp_controller *c = NULL;
    msp_controller_f64 *c64 = NULL;

    /* every status has a message */
    for (int i = MSP_OK; i <= MSP_BAD_HANDLE; i++) {
        const char *m = msp_status_str((msp_status)i);
        EXPECT(m != NULL && strlen(m) > 0);
    }
    EXPECT(strcmp(msp_status_str(-1), "unknown status") == 0);
    EXPECT(strcmp(msp_status_str(1000), "unknown status") == 0);

    /* tuning: NaN, negative, null */
    msp_smith_config sc;
    EXPECT(msp_tune_smith_fopdt(NAN, 40.2f, 93.9f, 0.939f, 0.0f, &sc) == MSP_NOT_FINITE);
    EXPECT(msp_tune_smith_fopdt(5.6f, -1.0f, 93.9f, 0.939f, 0.0f, &sc) == MSP_NOT_POSITIVE);
    EXPECT(msp_tune_smith_fopdt(5.6f, 40.2f, -1.0f, 0.939f, 0.0f, &sc) == MSP_NEGATIVE);
    EXPECT(msp_tune_smith_fopdt(5.6f, 40.2f, 93.9f, 0.0f, 0.0f, &sc) == MSP_NOT_POSITIVE);
    EXPECT(msp_tune_smith_fopdt(5.6f, 40.2f, 93.9f, 0.939f, NAN, &sc) == MSP_NOT_FINITE);
    EXPECT(msp_tune_smith_fopdt(5.6f, 40.2f, 93.9f, 0.939f, 0.0f, NULL) == MSP_NULL_POINTER);
    /* a PI at a crossover with a phase margin: pidtune's Kp 0.0501, Ti 47.3
       for the MathWorks process; a crossover where the controller would
       have to lead, a null model, a NaN phase margin */
    msp_model mw = {MSP_FOPDT, 5.6f, 40.2f, 93.9f};
    msp_pid_config xc;
    EXPECT(msp_tune_pid_crossover(&mw, 0.006f, 60.0f, 0, 0.0939f, &xc) == MSP_OK);
    EXPECT(fabsf(xc.pid.kp - 0.0501f) < 5e-5f && fabsf(xc.pid.ti - 47.3f) < 0.05f);
    EXPECT(xc.pid.td == 0.0f && xc.ts == 0.0939f);
    EXPECT(msp_tune_pid_crossover(&mw, 0.006f, 60.0f, 1, 0.0939f, &xc) == MSP_OK);
    EXPECT(fabsf(xc.pid.td - xc.pid.ti / 4.0f) < 1e-4f);
    EXPECT(msp_tune_pid_crossover(&mw, 0.1f, 60.0f, 0, 0.0939f, &xc) == MSP_UNSUPPORTED);
    EXPECT(msp_tune_pid_crossover(NULL, 0.006f, 60.0f, 0, 0.0939f, &xc) == MSP_NULL_POINTER);
    EXPECT(msp_tune_pid_crossover(&mw, 0.006f, NAN, 0, 0.0939f, &xc) != MSP_OK);
    EXPECT(msp_tune_pid_crossover(&mw, 0.006f, 60.0f, 0, 0.0939f, NULL) == MSP_NULL_POINTER);
    msp_karan_dey_config kc;
    EXPECT(msp_tune_karan_dey_ipdt(0.2f, NAN, 0.074f, 0.0f, &kc) == MSP_NOT_FINITE);
    EXPECT(msp_tune_karan_dey_ipdt(0.2f, 7.4f, -0.074f, 0.0f, &kc) == MSP_NOT_POSITIVE);
    EXPECT(msp_tune_karan_dey_ipdt(0.2f, 7.4f, 0.074f, 0.0f, NULL) == MSP_NULL_POINTER);
    msp_smith_config_f64 sc64;
    EXPECT(msp_tune_smith_fopdt_f64(5.6, 40.2, 93.9, NAN, 0.0, &sc64) == MSP_NOT_FINITE);
    msp_karan_dey_config_f64 kc64;
    EXPECT(msp_tune_karan_dey_ipdt_f64(0.2, 7.4, 0.074, NAN, &kc64) == MSP_NOT_FINITE);

    /* the good tunings */
    EXPECT(msp_tune_smith_fopdt(5.6f, 40.2f, 93.9f, 0.939f, 0.0f, &sc) == MSP_OK);
    EXPECT(msp_tune_karan_dey_ipdt(0.2f, 7.4f, 0.074f, 0.0f, &kc) == MSP_OK);
    EXPECT(msp_tune_smith_fopdt_f64(5.6, 40.2, 93.9, 0.939, 0.0, &sc64) == MSP_OK);
    EXPECT(msp_tune_karan_dey_ipdt_f64(0.2, 7.4, 0.074, 0.0, &kc64) == MSP_OK);

    /* sizes: null config, NaN, a dead time too long for any buffer; status may be null */
    EXPECT(msp_smith_size(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);
    EXPECT(msp_smith_size(NULL, 0, NULL) == 0);
    msp_smith_config bad = sc;
    bad.model.theta = NAN;
    EXPECT(msp_smith_size(&bad, 0, &s) == 0 && s == MSP_NOT_FINITE);
    bad = sc;
    bad.model.theta = 1e30f;
    EXPECT(msp_smith_size(&bad, 0, &s) == 0 && s == MSP_DEAD_TIME_TOO_LONG);
    bad = sc;
    bad.pid.ti = 0.0f;
    EXPECT(msp_smith_size(&bad, 0, &s) == 0 && s == MSP_NOT_POSITIVE);
    bad = sc;
    bad.pid.u_min = 1.0f;
    bad.pid.u_max = -1.0f;
    EXPECT(msp_smith_size(&bad, 0, &s) == 0 && s == MSP_INVALID_LIMITS);
    size_t need = msp_smith_size(&sc, 0, &s);
    EXPECT(s == MSP_OK && need > 100 * sizeof(float));
    EXPECT(msp_smith_size(&sc, 1000, &s) >= need + 900 * sizeof(float) && s == MSP_OK);
    EXPECT(msp_karan_dey_size(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);
    EXPECT(msp_fsp_size(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);
    EXPECT(msp_pid_size(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);
    EXPECT(msp_smith_size_f64(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);
    EXPECT(msp_karan_dey_size_f64(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);
    EXPECT(msp_fsp_size_f64(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);
    EXPECT(msp_pid_size_f64(NULL, 0, &s) == 0 && s == MSP_NULL_POINTER);

    /* init: null buffer, null config, null out, too small, bad parameters */
    EXPECT(msp_smith_init(NULL, sizeof memory, &sc, &c) == MSP_NULL_POINTER);
    EXPECT(msp_smith_init(memory, sizeof memory, NULL, &c) == MSP_NULL_POINTER);
    EXPECT(msp_smith_init(memory, sizeof memory, &sc, NULL) == MSP_NULL_POINTER);
    EXPECT(msp_smith_init(memory, 8, &sc, &c) == MSP_BUFFER_TOO_SMALL);
    EXPECT(msp_smith_init(memory, need / 2, &sc, &c) == MSP_BUFFER_TOO_SMALL);
    bad = sc;
    bad.pid.kp = NAN;
    EXPECT(msp_smith_init(memory, sizeof memory, &bad, &c) == MSP_NOT_FINITE);
    bad = sc;
    bad.model.kind = MSP_UFOPDT; /* the classic predictor leaves an unstable pole in the loop */
    EXPECT(msp_smith_init(memory, sizeof memory, &bad, &c) == MSP_UNSUPPORTED);
    bad.model.kind = 7; /* no such kind */
    EXPECT(msp_smith_size(&bad, 0, &s) == 0 && s == MSP_OUT_OF_RANGE);
    EXPECT(msp_smith_init(memory, sizeof memory, &bad, &c) == MSP_OUT_OF_RANGE);
    msp_karan_dey_config kbad = kc;
    kbad.gamma = -1.0f;
    EXPECT(msp_karan_dey_init(memory, sizeof memory, &kbad, &c) == MSP_NEGATIVE);
    kbad = kc;
    kbad.ts = NAN;
    EXPECT(msp_karan_dey_init(memory, sizeof memory, &kbad, &c) == MSP_NOT_FINITE);
    EXPECT(msp_karan_dey_init(memory, 16, &kc, &c) == MSP_BUFFER_TOO_SMALL);
    kbad = kc;
    kbad.model.kind = MSP_FOPDT; /* designed for integrating plants */
    EXPECT(msp_karan_dey_init(memory, sizeof memory, &kbad, &c) == MSP_UNSUPPORTED);

    msp_fsp_config fc = {
        .ts = 0.06f,
        .model = {.kind = MSP_UFOPDT, .k = 5.0f, .tau = 100.0f, .theta = 6.0f},
        .pid = {.kp = 6.87f, .ti = 12.36f, .td = 0.0f, .u_min = -INFINITY, .u_max = INFINITY},
        .tf = 3.0f,
    };
    msp_fsp_config fbad = fc;
    fbad.tf = 0.0f;
    EXPECT(msp_fsp_size(&fbad, 0, &s) == 0 && s == MSP_NOT_POSITIVE);
    EXPECT(msp_fsp_init(memory, sizeof memory, &fbad, &c) == MSP_NOT_POSITIVE);
    fbad = fc;
    fbad.model.theta = 6.03f; /* not whole samples */
    EXPECT(msp_fsp_init(memory, sizeof memory, &fbad, &c) == MSP_UNSUPPORTED);
    /* whole samples whose float quotient comes out just above: 0.3 s and
       1.08 s at 0.06 s are 5.0000005 and 18.000002 samples in float */
    fbad.model.theta = 0.3f;
    EXPECT(msp_fsp_init(memory, sizeof memory, &fbad, &c) == MSP_OK);
    fbad.model.theta = 1.08f;
    EXPECT(msp_fsp_init(memory, sizeof memory, &fbad, &c) == MSP_OK);
    size_t fneed = msp_fsp_size(&fc, 0, &s);
    EXPECT(s == MSP_OK && fneed > 0);
    EXPECT(msp_fsp_init(memory, fneed / 2, &fc, &c) == MSP_BUFFER_TOO_SMALL);

    msp_pid_config pc = {.ts = 0.1f, .pid = {.kp = 1.0f, .ti = 0.0f, .td = 0.0f,
                                             .u_min = -INFINITY, .u_max = INFINITY}};
    EXPECT(msp_pid_init(memory, sizeof memory, &pc, &c) == MSP_NOT_POSITIVE);
    pc.pid.ti = INFINITY; /* a P controller */
    EXPECT(msp_pid_init(memory, 4, &pc, &c) == MSP_BUFFER_TOO_SMALL);

    /* update, reset and fault on null and foreign handles */
    EXPECT(isnan(msp_update(NULL, 1.0f, 0.0f)));
    EXPECT(msp_reset(NULL) == MSP_NULL_POINTER);
    EXPECT(msp_fault(NULL));
    /* not a handle: every call checks the tag, the per-sample one too */
    memset(memory, 0xA5, 256);
    EXPECT(msp_reset((msp_controller *)memory) == MSP_BAD_HANDLE);
    EXPECT(msp_fault((msp_controller *)memory));
    EXPECT(msp_reset((msp_controller *)(memory + 1)) == MSP_BAD_HANDLE);
    EXPECT(isnan(msp_update((msp_controller *)memory, 1.0f, 0.0f)));
    EXPECT(isnan(msp_update_f64((msp_controller_f64 *)(memory + 1), 1.0, 0.0)));
    memset(memory, 0, 256);
    EXPECT(isnan(msp_update((msp_controller *)memory, 1.0f, 0.0f)));
    EXPECT(isnan(msp_update_f64((msp_controller_f64 *)memory, 1.0, 0.0)));
    EXPECT(isnan(msp_update_f64(NULL, 1.0, 0.0)));
    EXPECT(msp_reset_f64(NULL) == MSP_NULL_POINTER);
    EXPECT(msp_fault_f64(NULL));

    /* the good calls, at an odd address: every scheme in both precisions */
    unsigned char *odd = memory + 1;
    size_t room = sizeof memory - 1;
    EXPECT(msp_smith_init(odd, room, &sc, &c) == MSP_OK && c != NULL);
    EXPECT(msp_update(c, 1.0f, 0.0f) > 0.0f);
    EXPECT(!msp_fault(c));
    EXPECT(msp_update(c, NAN, 0.0f) == msp_update(c, NAN, 0.0f)); /* held */
    EXPECT(msp_fault(c));
    EXPECT(msp_reset(c) == MSP_OK);
    /* a valid handle cleared by memset is no handle */
    EXPECT(msp_smith_init(odd, room, &sc, &c) == MSP_OK);
    memset(odd, 0, 64);
    EXPECT(isnan(msp_update(c, 1.0f, 0.0f)));
    EXPECT(msp_smith_init(odd, room, &sc, &c) == MSP_OK);
    /* a float handle is not a double one */
    EXPECT(msp_reset_f64((msp_controller_f64 *)c) == MSP_BAD_HANDLE);
    EXPECT(msp_fault_f64((msp_controller_f64 *)c));
    EXPECT(msp_karan_dey_init(odd, room, &kc, &c) == MSP_OK && msp_update(c, 1.0f, 0.0f) > 0.0f);
    /* a finite measurement too large to compute with (beyond 2^32 in float)
       is a fault, held, and clears with the next usable one */
    {
        float before = msp_update(c, 1.0f, 0.0f);
        float spike = msp_update(c, 1.0f, 1e38f);
        EXPECT(isfinite(spike) && spike == before && msp_fault(c));
        EXPECT(isfinite(msp_update(c, 1.0f, -5e9f)) && msp_fault(c));
        EXPECT(isfinite(msp_update(c, 1.0f, 0.0f)) && !msp_fault(c));
    }
    EXPECT(msp_fsp_init(odd, room, &fc, &c) == MSP_OK && msp_update(c, 1.0f, 0.0f) > 0.0f);
    EXPECT(msp_pid_init(odd, room, &pc, &c) == MSP_OK && msp_update(c, 1.0f, 0.0f) == 1.0f);
    EXPECT(msp_smith_init_f64(odd, room, &sc64, &c64) == MSP_OK &&
           msp_update_f64(c64, 1.0, 0.0) > 0.0);
    EXPECT(msp_karan_dey_init_f64(odd, room, &kc64, &c64) == MSP_OK &&
           msp_update_f64(c64, 1.0, 0.0) > 0.0);
    EXPECT(msp_reset_f64(c64) == MSP_OK && !msp_fault_f64(c64));
    msp_fsp_config_f64 fc64 = {
        .ts = 0.06,
        .model = {.kind = MSP_UFOPDT, .k = 5.0, .tau = 100.0, .theta = 6.0},
        .pid = {.kp = 6.87, .ti = 12.36, .td = 0.0, .u_min = -INFINITY, .u_max = INFINITY},
        .tf = 3.0,
    };
    EXPECT(msp_fsp_init_f64(odd, room, &fc64, &c64) == MSP_OK && msp_update_f64(c64, 1.0, 0.0) > 0.0);
    msp_pid_config_f64 pc64 = {.ts = 0.1, .pid = {.kp = 2.0, .ti = INFINITY, .td = 0.0,
                                                  .u_min = -1.0, .u_max = 1.0}};
    EXPECT(msp_pid_init_f64(odd, room, &pc64, &c64) == MSP_OK && msp_update_f64(c64, 1.0, 0.0) == 1.0);
    EXPECT(msp_pid_init_f64(odd, room, NULL, &c64) == MSP_NULL_POINTER);
    /* the first update: after init or reset the first sample is the
       derivative's reference (no kick); after reset_to_rest it differences
       against zero, the transfer function's initial condition:
       kp + kp·td/(td/10 + ts) = 0.5 + 0.5·2/(0.2 + 0.1) */
    {
        msp_pid_config_f64 pd = {.ts = 0.1, .pid = {.kp = 0.5, .ti = 4.0, .td = 2.0,
                                                    .u_min = -INFINITY, .u_max = INFINITY}};
        EXPECT(msp_pid_init_f64(odd, room, &pd, &c64) == MSP_OK && msp_update_f64(c64, 1.0, 0.0) == 0.5);
        EXPECT(msp_reset_f64(c64) == MSP_OK && msp_update_f64(c64, 1.0, 0.0) == 0.5);
        EXPECT(msp_reset_to_rest_f64(c64) == MSP_OK &&
               fabs(msp_update_f64(c64, 1.0, 0.0) - (0.5 + 1.0 / 0.3)) < 1e-14);
        EXPECT(msp_reset_to_rest(NULL) == MSP_NULL_POINTER);
    }

    /* operation: manual and back to auto without a bump, the applied value,
       a run-time dead time within the buffer */
    {
        size_t room_for_150 = msp_smith_size(&sc, 150, &s);
        EXPECT(s == MSP_OK && room_for_150 <= room);
        EXPECT(msp_smith_init(odd, room_for_150, &sc, &c) == MSP_OK);
        float x = 0.0f, last = 0.0f;
        for (int i = 0; i < 50; i++) {
            last = msp_update(c, 1.0f, x);
        }
        EXPECT(msp_manual(c, last + 0.1f) == MSP_OK);
        EXPECT(msp_update(c, 1.0f, x) == last + 0.1f);
        EXPECT(msp_update(c, 1.0f, x) == last + 0.1f);
        EXPECT(msp_applied(c, 0.0f) == MSP_OK); /* ignored in manual: the held value was applied */
        EXPECT(msp_auto(c) == MSP_OK);
        float first = msp_update(c, 1.0f, x);
        EXPECT(fabsf(first - (last + 0.1f)) < 5e-3f); /* one sample of the law */
        EXPECT(msp_applied(c, first - 0.05f) == MSP_OK);
        EXPECT(isfinite(msp_update(c, 1.0f, x)));
        EXPECT(msp_manual(c, NAN) == MSP_NOT_FINITE);
        EXPECT(msp_applied(c, INFINITY) == MSP_NOT_FINITE);
        EXPECT(msp_set_dead_time(c, 120.0f) == MSP_OK);
        EXPECT(msp_set_dead_time(c, 160.0f) == MSP_DEAD_TIME_TOO_LONG);
        EXPECT(msp_set_dead_time(c, -1.0f) == MSP_NEGATIVE);
        EXPECT(msp_manual(NULL, 0.0f) == MSP_NULL_POINTER);
        EXPECT(msp_auto(NULL) == MSP_NULL_POINTER);
        EXPECT(msp_applied(NULL, 0.0f) == MSP_NULL_POINTER);
        EXPECT(msp_set_dead_time(NULL, 1.0f) == MSP_NULL_POINTER);
        EXPECT(msp_manual((msp_controller *)memory, 0.0f) == MSP_BAD_HANDLE);
        float before = msp_update(c, 1.0f, x);
        EXPECT(msp_retune(c, MSP_KP, 2.0f * sc.pid.kp) == MSP_OK);
        EXPECT(msp_retune(c, MSP_TI, INFINITY) == MSP_OK);
        EXPECT(fabsf(msp_update(c, 1.0f, x) - before) < 5e-3f);
        EXPECT(msp_retune(c, 7, 1.0f) == MSP_OUT_OF_RANGE);
        EXPECT(msp_retune(c, MSP_TI, 0.0f) == MSP_NOT_POSITIVE);
        EXPECT(msp_retune(c, MSP_KP, NAN) == MSP_NOT_FINITE);
        EXPECT(msp_retune(NULL, MSP_KP, 1.0f) == MSP_NULL_POINTER);
        EXPECT(msp_karan_dey_init(odd, room, &kc, &c) == MSP_OK);
        EXPECT(msp_retune(c, MSP_KP, 1.0f) == MSP_UNSUPPORTED);
        EXPECT(msp_retune(c, MSP_TI, 30.0f) == MSP_OK);
        EXPECT(msp_fsp_init(odd, room, &fc, &c) == MSP_OK);
        EXPECT(msp_set_dead_time(c, 90.0f) == MSP_UNSUPPORTED);
        EXPECT(msp_smith_init_f64(odd, room, &sc64, &c64) == MSP_OK);
        EXPECT(msp_manual_f64(c64, 0.25) == MSP_OK && msp_update_f64(c64, 1.0, 0.0) == 0.25);
        EXPECT(msp_applied_f64(c64, 0.2) == MSP_OK && msp_auto_f64(c64) == MSP_OK);
        EXPECT(msp_set_dead_time_f64(c64, 99.0) == MSP_OK);
        EXPECT(msp_set_dead_time_f64(c64, 1e9) == MSP_DEAD_TIME_TOO_LONG);
    }

    /* the relay experiment */
    msp_relay_config rc;
    EXPECT(msp_relay_default_config(0.0f, 0.1f, &rc) == MSP_OUT_OF_RANGE);
    EXPECT(msp_relay_default_config(1.0f, NAN, &rc) == MSP_NOT_FINITE);
    EXPECT(msp_relay_default_config(1.0f, 0.1f, NULL) == MSP_NULL_POINTER);
    EXPECT(msp_relay_default_config(1.0f, 0.1f, &rc) == MSP_OK);
    msp_relay_config rbad = rc;
    rbad.bias = 2.0f;
    msp_relay *relay = NULL;
    EXPECT(msp_relay_init(memory, sizeof memory, &rbad, &relay) == MSP_OUT_OF_RANGE);
    rbad = rc;
    rbad.cycles = 0;
    EXPECT(msp_relay_init(memory, sizeof memory, &rbad, &relay) == MSP_OUT_OF_RANGE);
    EXPECT(msp_relay_init(NULL, sizeof memory, &rc, &relay) == MSP_NULL_POINTER);
    EXPECT(msp_relay_init(memory, sizeof memory, NULL, &relay) == MSP_NULL_POINTER);
    EXPECT(msp_relay_init(memory, 4, &rc, &relay) == MSP_BUFFER_TOO_SMALL);
    EXPECT(isnan(msp_relay_update(NULL, 0.0f)));
    msp_relay_state st;
    msp_relay_result rr;
    EXPECT(msp_relay_poll(NULL, &st, &rr) == MSP_NULL_POINTER);
    EXPECT(msp_relay_poll((msp_relay *)memory, &st, &rr) == MSP_BAD_HANDLE);
    EXPECT(msp_relay_ipdt(NULL, NULL) == MSP_NULL_POINTER);
    msp_model m;
    memset(&rr, 0, sizeof rr);
    EXPECT(msp_relay_ipdt(&rr, &m) != MSP_OK); /* a zero period */
    EXPECT(msp_relay_fopdt(&rr, NAN, &m) == MSP_NOT_FINITE);
    EXPECT(msp_relay_init(odd, room, &rc, &relay) == MSP_OK);
    EXPECT(msp_relay_poll(relay, NULL, NULL) == MSP_NULL_POINTER);
    EXPECT(msp_relay_update(relay, NAN) == 0.0f); /* a bad measurement ends it at u0 */
    EXPECT(msp_relay_poll(relay, &st, NULL) == MSP_OK && st == MSP_RELAY_BAD_MEASUREMENT);

    /* a whole experiment: the relay on the IPDT plant 0.2 e^{-2 s}/s sampled
       every 0.01 s (an integrator behind a 200-sample delay), identified back */
    {
        EXPECT(msp_relay_default_config(1.0f, 0.01f, &rc) == MSP_OK);
        EXPECT(msp_relay_init(odd, room, &rc, &relay) == MSP_OK);
        st = relay_on(relay, 1.0f, 0.2f * 0.01f, 200, &rr);
        EXPECT(st == MSP_RELAY_DONE);
        EXPECT(msp_relay_ipdt(&rr, &m) == MSP_OK && m.kind == MSP_IPDT);
        EXPECT(fabsf(m.k - 0.2f) < 0.01f && fabsf(m.theta - 2.0f) < 0.05f);
        printf("relay: period %.4g s, identified k %.4g, theta %.4g s\n", (double)rr.period,
               (double)m.k, (double)m.theta);
        /* and the Karan-Dey predictor tuned from it */
        EXPECT(msp_tune_karan_dey_ipdt(m.k, m.theta, 0.01f, 0.0f, &kc) == MSP_OK);
        EXPECT(msp_karan_dey_init(odd, room, &kc, &c) == MSP_OK);
    }

    /* the unstable FOPDT 2 e^{-s}/(3s - 1) sampled every 0.01 s (x' = (x + 2u(t - 1))/3:
       x[k+1] = a x + 2(a - 1) v, a = e^{0.01/3}), a biased relay, identified back;
       a symmetric relay's cycle does not determine it */
    {
        const float a = expf(0.01f / 3.0f);
        EXPECT(msp_relay_default_config(1.0f, 0.01f, &rc) == MSP_OK);
        rc.bias = 0.2f;
        EXPECT(msp_relay_init(odd, room, &rc, &relay) == MSP_OK);
        st = relay_on(relay, a, 2.0f * (a - 1.0f), 100, &rr);
        EXPECT(st == MSP_RELAY_DONE);
        EXPECT(msp_relay_ufopdt(&rr, &m) == MSP_OK && m.kind == MSP_UFOPDT);
        EXPECT(fabsf(m.k - 2.0f) < 0.02f && fabsf(m.tau - 3.0f) < 0.03f && fabsf(m.theta - 1.0f) < 0.01f);
        printf("relay, unstable: period %.4g s, identified k %.4g, tau %.4g s, theta %.4g s\n",
               (double)rr.period, (double)m.k, (double)m.tau, (double)m.theta);
        EXPECT(msp_relay_ufopdt(NULL, &m) == MSP_NULL_POINTER);
        rr.bias = 0.0f;
        EXPECT(msp_relay_ufopdt(&rr, &m) == MSP_UNSUPPORTED);
    }

    /* a finite measurement at the float range's end is a fault, never a
       latched NaN: later normal samples give finite outputs again */
    {
        msp_pid_config lim = pc;
        lim.pid.u_min = -10.0f;
        lim.pid.u_max = 10.0f;
        EXPECT(msp_pid_init(odd, room, &lim, &c) == MSP_OK);
        EXPECT(isfinite(msp_update(c, 0.0f, FLT_MAX)));
        float u = 0.0f;
        for (int i = 0; i < 20; i++) {
            u = msp_update(c, 1.0f, 0.5f);
        }
        EXPECT(isfinite(u) && !msp_fault(c));
        EXPECT(msp_pid_init(odd, room, &pc, &c) == MSP_OK);
        EXPECT(isfinite(msp_update(c, 0.0f, FLT_MAX)));
        EXPECT(isfinite(msp_update(c, 1.0f, 0.5f)) && !msp_fault(c));
    }


    /* adaptive dead-time compensation: bad arguments, then an adaptive Smith
       predictor on e^-1s/(4s+1) at 0.1 s whose process lag doubles at sample
       1500 (the model in use becomes the process's), and the identifier alone
       on the exact sampled data of 2 e^-1.25s/(4s+1) */
    {
        msp_smith_config sc;
        msp_adaptive_config ac;
        msp_adaptive_state st_;
        msp_adaptive *ad = NULL;
        msp_estimator_config ec;
        msp_estimate e;
        msp_estimator *est = NULL;
        EXPECT(msp_tune_smith_fopdt(1.0f, 4.0f, 1.0f, 0.1f, 2.0f, &sc) == MSP_OK);
        EXPECT(msp_adaptive_default_config(NULL, &ac) == MSP_NULL_POINTER);
        EXPECT(msp_adaptive_default_config(&sc, NULL) == MSP_NULL_POINTER);
        EXPECT(msp_adaptive_default_config(&sc, &ac) == MSP_OK);
        EXPECT(ac.adapt.d_min == 4 && ac.adapt.d_max == 19 && ac.adapt.apply == 1);
        EXPECT(ac.adapt.decimation == 1 && ac.adapt.prefilter == 0.0f && ac.adapt.bound == 4.0f);
        {
            /* at a tenth of the period (100 samples of dead time) the
               estimator keeps its time scale: a sample of its own per ten */
            msp_smith_config fine;
            msp_adaptive_config fac;
            EXPECT(msp_tune_smith_fopdt(1.0f, 4.0f, 1.0f, 0.01f, 2.0f, &fine) == MSP_OK);
            EXPECT(msp_adaptive_default_config(&fine, &fac) == MSP_OK);
            EXPECT(fac.adapt.decimation == 10 && fac.adapt.d_min == 4 && fac.adapt.d_max == 19);
            fac.adapt.decimation = 0;
            EXPECT(msp_adaptive_size(&fac, &s) == 0 && s == MSP_OUT_OF_RANGE);
            fac.adapt.decimation = 10;
            fac.adapt.bound = 1.0f;
            EXPECT(msp_adaptive_size(&fac, &s) == 0 && s == MSP_OUT_OF_RANGE);
        }
        msp_adaptive_config bad = ac;
        bad.adapt.forgetting = 1.5f;
        EXPECT(msp_adaptive_size(&bad, &s) == 0 && s == MSP_OUT_OF_RANGE);
        bad = ac;
        bad.adapt.d_max = ac.adapt.d_min + 16; /* 17 candidates */
        EXPECT(msp_adaptive_size(&bad, &s) == 0 && s == MSP_OUT_OF_RANGE);
        bad.adapt.d_max = ac.adapt.d_min - 1;
        EXPECT(msp_adaptive_size(&bad, &s) == 0 && s == MSP_OUT_OF_RANGE);
        bad = ac;
        bad.adapt.band = -1.0f;
        EXPECT(msp_adaptive_size(&bad, &s) == 0 && s != MSP_OK);
        bad = ac;
        bad.adapt.d_min = 600; /* beyond the history */
        bad.adapt.d_max = 615;
        unsigned char *abuf = adapt_memory + 3;
        EXPECT(msp_adaptive_init(abuf, sizeof adapt_memory - 3, &bad, &ad) != MSP_OK);
        size_t need = msp_adaptive_size(&ac, &s);
        EXPECT(s == MSP_OK && need > 0 && need <= sizeof adapt_memory - 3);
        EXPECT(msp_adaptive_init(abuf, need / 2, &ac, &ad) == MSP_BUFFER_TOO_SMALL);
        EXPECT(isnan(msp_adaptive_update(NULL, 1.0f, 0.0f)));
        EXPECT(isnan(msp_adaptive_update((msp_adaptive *)(void *)memory, 1.0f, 0.0f)));
        EXPECT(msp_adaptive_read(NULL, &st_) == MSP_NULL_POINTER);
        EXPECT(msp_adaptive_init(abuf, need, &ac, &ad) == MSP_OK);
        EXPECT(msp_adaptive_read(ad, NULL) == MSP_NULL_POINTER);
        /* nothing learnt before any data */
        EXPECT(msp_adaptive_read(ad, &st_) == MSP_OK && st_.learnt == 0 && st_.onsets == 0
               && st_.restarts == 0 && st_.responses == 0 && st_.responses_used == 0
               && st_.responses_ramps == 0 && st_.adapt_changes == 0);
        /* a controller handle is not an adaptive one */
        EXPECT(msp_adaptive_freeze((msp_adaptive *)(void *)c, 1) == MSP_BAD_HANDLE);
        lag_doubles(ad, 9000, NULL);
        EXPECT(msp_adaptive_read(ad, &st_) == MSP_OK);
        EXPECT(fabsf(st_.tau_model - 8.0f) < 0.8f && fabsf(st_.k_model - 1.0f) < 0.05f
               && fabsf(st_.theta_model - 1.0f) <= 0.1f && st_.adapt_changes >= 1 && !st_.frozen
               && st_.learnt > 0 && st_.adapt_kind >= 1 && st_.adapt_kind <= 8
               && st_.responses_used <= st_.responses
               && st_.responses_used + st_.responses_ramps <= st_.responses
               && fabsf(st_.tau_hat - 8.0f) < 0.8f && st_.evidence > 0.0f);
        printf("adaptive: model k %.4g, tau %.4g s, theta %.4g s after %u changes, "
               "%u samples learnt from, %u load onsets, %u restarts, %u responses compared in levels (%u taken as evidence)\n",
               (double)st_.k_model, (double)st_.tau_model, (double)st_.theta_model, (unsigned)st_.adapt_changes,
               (unsigned)st_.learnt, (unsigned)st_.onsets, (unsigned)st_.restarts, (unsigned)st_.responses,
               (unsigned)st_.responses_used);

        EXPECT(msp_estimator_default_config(0.0f, 4, &ec) == MSP_NOT_POSITIVE);
        EXPECT(msp_estimator_default_config(0.1f, 4, &ec) == MSP_OK);
        unsigned char *ebuf = estimator_memory + 1;
        EXPECT(msp_estimator_size() <= sizeof estimator_memory - 1);
        EXPECT(msp_estimator_init(ebuf, msp_estimator_size() / 2, &ec, &est) == MSP_BUFFER_TOO_SMALL);
        EXPECT(msp_estimator_init(ebuf, msp_estimator_size(), &ec, &est) == MSP_OK);
        EXPECT(msp_estimator_estimate(est, &e) == MSP_OK && isnan(e.k));
        const float a = expf(-0.1f / 4.0f);
        const float b0 = 2.0f * (1.0f - sqrtf(a)), b1 = 2.0f * (sqrtf(a) - a);
        float us[6000];
        float y = 0.0f;
        for (int k = 0; k < 6000; k++) {
            float u = (k / 150) % 2 ? 1.0f : -1.0f;
            EXPECT(msp_estimator_update(est, y, u, 1) == MSP_OK);
            us[k] = u;
            y = a * y + b0 * (k >= 12 ? us[k - 12] : 0.0f) + b1 * (k >= 13 ? us[k - 13] : 0.0f);
        }
        EXPECT(msp_estimator_estimate(est, &e) == MSP_OK);
        EXPECT(fabsf(e.k - 2.0f) < 0.01f && fabsf(e.tau - 4.0f) < 0.04f
               && fabsf(e.theta - 1.25f) < 0.02f);
        printf("estimator: k %.4g, tau %.4g s, theta %.4g s\n", (double)e.k, (double)e.tau,
               (double)e.theta);
        EXPECT(msp_estimator_update((msp_estimator *)(void *)ad, 0.0f, 0.0f, 1) == MSP_BAD_HANDLE);

        /* the monitor: the same data weighed against a model in use whose
           gain is 30 % low (1.4 for 2) and against the process's own */
        {
            msp_mismatch mm;
            const float gains[2] = {1.4f, 2.0f};
            float errors[2][2];
            EXPECT(msp_estimator_mismatch(est, 0, NULL) == MSP_NULL_POINTER);
            EXPECT(msp_estimator_set_reference(est, NULL) == MSP_NULL_POINTER);
            for (int i = 0; i < 2; i++) {
                msp_model ref = {MSP_FOPDT, gains[i], 4.0f, 1.25f};
                EXPECT(msp_estimator_init(ebuf, msp_estimator_size(), &ec, &est) == MSP_OK);
                EXPECT(msp_estimator_set_reference(est, &ref) == MSP_OK);
                EXPECT(msp_estimator_mismatch(est, 0, &mm) == MSP_OK && isnan(mm.error));
                y = 0.0f;
                for (int k = 0; k < 6000; k++) {
                    EXPECT(msp_estimator_update(est, y, us[k], 1) == MSP_OK);
                    y = a * y + b0 * (k >= 12 ? us[k - 12] : 0.0f)
                        + b1 * (k >= 13 ? us[k - 13] : 0.0f);
                }
                for (int recent = 0; recent < 2; recent++) {
                    EXPECT(msp_estimator_mismatch(est, recent, &mm) == MSP_OK);
                    errors[i][recent] = mm.error;
                }
            }
            /* a gain error shows as its size relative to the model's
               prediction, (2 - 1.4)/1.4 = 0.43: over the last response to
               1 %, over the long memory to 5 % (which holds the estimator's
               own first, unconverged responses); the right model as none */
            for (int recent = 0; recent < 2; recent++) {
                EXPECT(fabsf(errors[0][recent] - 0.6f / 1.4f) < (recent ? 0.01f : 0.05f) * 0.6f / 1.4f);
                EXPECT(errors[1][recent] < 0.01f);
            }
            printf("estimator monitor: error %.3g (long), %.3g (recent) for a model's gain 30 %% low; %.2g for the right model\n",
                   (double)errors[0][0], (double)errors[0][1], (double)errors[1][0]);
        }

        /* the candidates end at d_max: on the same data with d_max 10 (the
           process's 12.5 samples beyond it) no estimate is longer */
        EXPECT(ec.d_min == 4 && ec.d_max == 19);
        ec.d_max = 20;
        EXPECT(msp_estimator_init(ebuf, msp_estimator_size(), &ec, &est) == MSP_OUT_OF_RANGE);
        ec.d_max = 10;
        EXPECT(msp_estimator_init(ebuf, msp_estimator_size(), &ec, &est) == MSP_OK);
        y = 0.0f;
        unsigned longest = 0;
        for (int k = 0; k < 6000; k++) {
            EXPECT(msp_estimator_update(est, y, us[k], 1) == MSP_OK);
            y = a * y + b0 * (k >= 12 ? us[k - 12] : 0.0f) + b1 * (k >= 13 ? us[k - 13] : 0.0f);
            EXPECT(msp_estimator_estimate(est, &e) == MSP_OK);
            if (!isnan(e.k) && e.d > longest) {
                longest = e.d;
            }
        }
        EXPECT(longest <= 10); /* none past d_max (the process's 12 is beyond it) */
        printf("estimator with d_max 10: the longest dead time chosen %u samples\n", longest);
    }

    /* the adaptive Karan-Dey predictor on 0.5 e^-1s/s at 0.1 s whose gain
       rises 20 % at sample 1500: each change builds the predictor anew in the
       line the one in use does not hold, warms it up and hands over; the
       model in use becomes the process's and the loop stays bounded */
    {
        msp_karan_dey_config kd;
        msp_adaptive_karan_dey_config akc;
        msp_adaptive_state st_;
        msp_adaptive *ad = NULL;
        EXPECT(msp_tune_karan_dey_ipdt(0.5f, 1.0f, 0.1f, 0.0f, &kd) == MSP_OK);
        EXPECT(msp_adaptive_karan_dey_default_config(NULL, &akc) == MSP_NULL_POINTER);
        EXPECT(msp_adaptive_karan_dey_default_config(&kd, &akc) == MSP_OK);
        EXPECT(akc.adapt.d_min == 4 && akc.adapt.d_max == 19);
        msp_adaptive_karan_dey_config bad = akc;
        bad.adapt.lambda = NAN; /* every change is a redesign */
        EXPECT(msp_adaptive_karan_dey_size(&bad, &s) == 0 && s == MSP_NOT_FINITE);
        bad = akc;
        bad.karan_dey.model.kind = MSP_FOPDT;
        EXPECT(msp_adaptive_karan_dey_size(&bad, &s) == 0 && s != MSP_OK);
        size_t need = msp_adaptive_karan_dey_size(&akc, &s);
        msp_adaptive_config smith_ac;
        msp_smith_config sc;
        EXPECT(msp_tune_smith_fopdt(1.0f, 4.0f, 1.0f, 0.1f, 2.0f, &sc) == MSP_OK);
        EXPECT(msp_adaptive_default_config(&sc, &smith_ac) == MSP_OK);
        /* two lines where the Smith predictor has one */
        EXPECT(s == MSP_OK && need > msp_adaptive_size(&smith_ac, NULL));
        unsigned char *abuf = adapt_memory + 5;
        /* the Smith predictor's bytes (the same handle and candidates) hold
           one line, not the second */
        EXPECT(msp_adaptive_karan_dey_init(abuf, msp_adaptive_size(&smith_ac, NULL), &akc, &ad)
               == MSP_BUFFER_TOO_SMALL);
        EXPECT(msp_adaptive_karan_dey_init(abuf, need, &akc, &ad) == MSP_OK);
        float y = 0.0f, line[10] = {0}, peak = 0.0f;
        for (int k = 0; k < 12000; k++) {
            float r = (k / 300) % 2 == 0 ? 1.0f : 0.0f;
            float u = msp_adaptive_update(ad, r, y);
            float late = line[k % 10];
            line[k % 10] = u;
            y += 0.1f * (k < 1500 ? 0.5f : 0.6f) * late;
            /* the error at the end of each half period after 600 s */
            if (k > 6000 && k % 300 == 299 && fabsf(y - r) > peak) {
                peak = fabsf(y - r);
            }
        }
        EXPECT(msp_adaptive_read(ad, &st_) == MSP_OK);
        EXPECT(fabsf(st_.k_model - 0.6f) < 0.03f && isinf(st_.tau_model) && fabsf(st_.theta_model - 1.0f) <= 0.105f
               && st_.adapt_changes >= 1 && !st_.frozen);
        EXPECT(peak < 0.01f);
        printf("adaptive karan-dey: model k %.4g, theta %.4g s after %u changes; settled error "
               "after 600 s at most %.3g\n",
               (double)st_.k_model, (double)st_.theta_model, (unsigned)st_.adapt_changes, (double)peak);
    }

    /* the adaptive filtered Smith predictor on e^-1s/(4s+1) at 0.1 s whose
       lag doubles at sample 1500: redesigned for each model (its predictor
       in the other line, designed in the scratch), warmed up, handed over */
    {
        msp_fsp_config f = {
            .ts = 0.1f,
            .model = {.kind = MSP_FOPDT, .k = 1.0f, .tau = 4.0f, .theta = 1.0f},
            .pid = {.kp = 4.0f, .ti = 4.0f, .td = 0.0f, .u_min = -INFINITY, .u_max = INFINITY},
            .tf = 0.5f,
        };
        msp_adaptive_fsp_config afc;
        msp_adaptive_state st_;
        msp_adaptive *ad = NULL;
        EXPECT(msp_adaptive_fsp_default_config(&f, NULL) == MSP_NULL_POINTER);
        EXPECT(msp_adaptive_fsp_default_config(&f, &afc) == MSP_OK);
        msp_adaptive_fsp_config bad = afc;
        bad.fsp.model.kind = MSP_UFOPDT; /* the identifier's models are FOPDT and IPDT */
        EXPECT(msp_adaptive_fsp_size(&bad, &s) == 0 && s == MSP_UNSUPPORTED);
        bad = afc;
        bad.adapt.lambda = NAN;
        EXPECT(msp_adaptive_fsp_size(&bad, &s) == 0 && s == MSP_NOT_FINITE);
        size_t need = msp_adaptive_fsp_size(&afc, &s);
        EXPECT(s == MSP_OK && need > 0 && need <= sizeof adapt_memory - 7);
        unsigned char *abuf = adapt_memory + 7;
        EXPECT(msp_adaptive_fsp_init(abuf, need / 2, &afc, &ad) == MSP_BUFFER_TOO_SMALL);
        EXPECT(msp_adaptive_fsp_init(abuf, need, &afc, &ad) == MSP_OK);
        float worst = lag_doubles(ad, 12000, NULL);
        EXPECT(msp_adaptive_read(ad, &st_) == MSP_OK);
        EXPECT(fabsf(st_.tau_model - 8.0f) < 0.8f && fabsf(st_.k_model - 1.0f) < 0.05f
               && fabsf(st_.theta_model - 1.0f) <= 0.1f && st_.adapt_changes >= 1 && !st_.frozen);
        /* the model read back is the predictor's: a dead time of whole samples */
        EXPECT(fabsf(st_.theta_model / 0.1f - roundf(st_.theta_model / 0.1f)) < 1e-4f);
        EXPECT(worst < 0.01f);
        printf("adaptive fsp: model k %.4g, tau %.4g s, theta %.4g s after %u changes; settled "
               "error after 600 s at most %.3g\n",
               (double)st_.k_model, (double)st_.tau_model, (double)st_.theta_model, (unsigned)st_.adapt_changes,
               (double)worst);

        /* designed in the background: the update that applies a model
           leaves its design to msp_adaptive_design (called here between
           samples, as a background task would); the same models, a sample
           later each; without the call nothing is applied, and nothing
           breaks */
        msp_adaptive_state bg, idle;
        int designs = 0, none = 0;
        EXPECT(msp_adaptive_design(NULL, &none) == MSP_NULL_POINTER);
        EXPECT(msp_adaptive_design((msp_adaptive *)(void *)memory, &none) == MSP_BAD_HANDLE);
        afc.adapt.background_design = 1;
        EXPECT(msp_adaptive_fsp_init(abuf, need, &afc, &ad) == MSP_OK);
        EXPECT(msp_adaptive_design(ad, &none) == MSP_OK && none == 0);
        EXPECT(msp_adaptive_design(ad, NULL) == MSP_OK);
        float bg_worst = lag_doubles(ad, 12000, &designs);
        EXPECT(msp_adaptive_read(ad, &bg) == MSP_OK);
        EXPECT(designs >= 1 && !bg.frozen);
        EXPECT(fabsf(bg.tau_model - st_.tau_model) < 0.05f * st_.tau_model
               && fabsf(bg.k_model - st_.k_model) < 0.01f && bg.theta_model == st_.theta_model);
        EXPECT(bg_worst < 0.01f);
        EXPECT(msp_adaptive_fsp_init(abuf, need, &afc, &ad) == MSP_OK);
        lag_doubles(ad, 12000, NULL);
        EXPECT(msp_adaptive_read(ad, &idle) == MSP_OK);
        EXPECT(!idle.frozen && idle.tau_model == 4.0f && idle.k_model == 1.0f);
        printf("adaptive fsp designed in the background: %d designs, model k %.4g, tau %.4g s, "
               "theta %.4g s; without the calls, tau %.4g s\n",
               designs, (double)bg.k_model, (double)bg.tau_model, (double)bg.theta_model,
               (double)idle.tau_model);
    }

    printf("%s: %d failures\n", failures ? "FAIL" : "ok", failures);
    return failures ? 1 : 0;
}
