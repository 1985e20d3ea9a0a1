/*
 * A 2x2 plant from C: the Wood-Berry column (Wood & Berry 1973, minutes),
 * sampled every minute, under the decoupled Smith predictors and under
 * decentralized ones (msp_mimo2_*), against the column simulated here in C
 * (each channel y <- a y + K (1 - a) u[k - theta], output i the sum of row i).
 *
 * Checks, with exit status 1 where one fails: loop 1's set-point step leaves
 * output 2 where it was under the decoupler (to float rounding) and moves it
 * under the decentralized predictors; both loops settle on their set points;
 * the bad arguments give their statuses. Runs on the host and on a
 * Cortex-M4F (QEMU mps2-an386) alike.
 */
#include <stdio.h>
#include <math.h>

#include "msp.h"

#define SAMPLES 300
#define ROOM 8

static unsigned char memory[2048];

/* a failed check, named */
#define CHECK(cond, what)                          \
    do {                                           \
        if (!(cond)) {                             \
            printf("check failed: %s\n", what);    \
            bad = 1;                               \
        }                                          \
    } while (0)

/* channel (K, tau, theta) at 1 min: y[k+1] = a y[k] + b u[k - theta] */
typedef struct {
    float a, b, x;
    float line[ROOM];
    int head, d;
} channel;

static void channel_init(channel *c, float k, float tau, int theta) {
    c->a = expf(-1.0f / tau);
    c->b = k * (1.0f - c->a);
    c->x = 0.0f;
    for (int i = 0; i < ROOM; i++) c->line[i] = 0.0f;
    c->head = 0;
    c->d = theta;
}

/* holds u over the period, returns y[k+1] */
static float channel_step(channel *c, float u) {
    float late = c->line[(c->head + ROOM - c->d) % ROOM];
    c->line[c->head] = u;
    c->head = (c->head + 1) % ROOM;
    c->x = c->a * c->x + c->b * late;
    return c->x;
}

static const float K[4] = {12.8f, -18.9f, 6.6f, -19.4f};
static const float TAU[4] = {16.7f, 21.0f, 10.9f, 14.4f};
static const int THETA[4] = {1, 3, 7, 3};

/* the column's channels as models */
static void wood_berry(msp_model g[4]) {
    for (int i = 0; i < 4; i++) {
        g[i].kind = MSP_FOPDT;
        g[i].k = K[i];
        g[i].tau = TAU[i];
        g[i].theta = (float)THETA[i];
    }
}

/* runs the column under `decoupled` (1) or not (0): loop 1 steps to 1 at 0,
 * loop 2 to 1 at 150; returns the largest |y2| before 150 and y1, y2 at the end */
static int run(unsigned decoupled, float *cross, float *y1_end, float *y2_end) {
    msp_model g[4];
    wood_berry(g);
    msp_mimo2_config cfg;
    msp_status s = msp_tune_mimo2(g, 1.0f, decoupled, &cfg);
    if (s != MSP_OK) {
        printf("tune: %s\n", msp_status_str(s));
        return 1;
    }
    size_t need = msp_mimo2_size(&cfg, &s);
    if (s != MSP_OK || need > sizeof memory) {
        printf("size: %s (%u bytes)\n", msp_status_str(s), (unsigned)need);
        return 1;
    }
    msp_mimo2 *c = NULL;
    s = msp_mimo2_init(memory, sizeof memory, &cfg, &c);
    if (s != MSP_OK) {
        printf("init: %s\n", msp_status_str(s));
        return 1;
    }
    channel ch[4];
    for (int i = 0; i < 4; i++) channel_init(&ch[i], K[i], TAU[i], THETA[i]);
    float y[2] = {0.0f, 0.0f}, u[2], r[2];
    *cross = 0.0f;
    for (int k = 0; k < SAMPLES; k++) {
        r[0] = 1.0f;
        r[1] = k >= 150 ? 1.0f : 0.0f;
        if (msp_mimo2_update(c, r, y, u) != MSP_OK) return 1;
        if (k < 150 && fabsf(y[1]) > *cross) *cross = fabsf(y[1]);
        float y1 = channel_step(&ch[0], u[0]) + channel_step(&ch[1], u[1]);
        float y2 = channel_step(&ch[2], u[0]) + channel_step(&ch[3], u[1]);
        y[0] = y1;
        y[1] = y2;
    }
    *y1_end = y[0];
    *y2_end = y[1];
    printf("%s: %u bytes; output 2 before its own step moved by %.3g; y = %.6f, %.6f at %d min\n",
           decoupled ? "decoupled" : "decentralized", (unsigned)need, *cross, *y1_end, *y2_end,
           SAMPLES);
    return 0;
}

int main(void) {
    int bad = 0;
    float cross, y1, y2;
    if (run(1, &cross, &y1, &y2)) return 1;
    CHECK(!(cross > 1e-5f || fabsf(y1 - 1.0f) > 1e-3f || fabsf(y2 - 1.0f) > 1e-3f), "cross > 1e-5f || fabsf(y1 - 1.0f) > 1e-3f || fabsf(y2 - 1.0f) > 1e-3f");
    if (run(0, &cross, &y1, &y2)) return 1;
    CHECK(!(cross < 0.05f || fabsf(y1 - 1.0f) > 1e-2f || fabsf(y2 - 1.0f) > 1e-2f), "cross < 0.05f || fabsf(y1 - 1.0f) > 1e-2f || fabsf(y2 - 1.0f) > 1e-2f");

    /* the bad arguments */
    msp_status s;
    msp_mimo2_config cfg;
    msp_model g[4];
    wood_berry(g);
    CHECK(!(msp_tune_mimo2(NULL, 1.0f, 1, &cfg) != MSP_NULL_POINTER), "msp_tune_mimo2(NULL, 1.0f, 1, &cfg) != MSP_NULL_POINTER");
    CHECK(!(msp_mimo2_size(NULL, &s) != 0 || s != MSP_NULL_POINTER), "msp_mimo2_size(NULL, &s) != 0 || s != MSP_NULL_POINTER");
    /* g12 answering sooner than g11 cannot be decoupled */
    g[1].theta = 0.0f;
    CHECK(msp_tune_mimo2(g, 1.0f, 1, &cfg) == MSP_UNSUPPORTED, "an advance is refused");
    CHECK(msp_tune_mimo2(g, 1.0f, 0, &cfg) == MSP_OK, "decentralized needs none");
    cfg.decoupled = 1;
    msp_mimo2 *c = NULL;
    CHECK(msp_mimo2_init(memory, sizeof memory, &cfg, &c) == MSP_UNSUPPORTED, "init refuses it too");
    g[1].theta = 3.0f;
    g[2].kind = MSP_IPDT;
    CHECK(!(msp_tune_mimo2(g, 1.0f, 1, &cfg) != MSP_UNSUPPORTED), "msp_tune_mimo2(g, 1.0f, 1, &cfg) != MSP_UNSUPPORTED");
    g[2].kind = MSP_FOPDT;
    CHECK(!(msp_tune_mimo2(g, 1.0f, 1, &cfg) != MSP_OK), "msp_tune_mimo2(g, 1.0f, 1, &cfg) != MSP_OK");
    CHECK(!(msp_mimo2_init(memory, 16, &cfg, &c) != MSP_BUFFER_TOO_SMALL), "msp_mimo2_init(memory, 16, &cfg, &c) != MSP_BUFFER_TOO_SMALL");
    float r[2] = {1, 0}, y[2] = {0, 0}, u[2] = {7, 7};
    CHECK(!(msp_mimo2_update(NULL, r, y, u) != MSP_NULL_POINTER || u[0] != 7.0f), "msp_mimo2_update(NULL, r, y, u) != MSP_NULL_POINTER || u[0] != 7.0f");
    /* a single-loop handle is not a 2x2 one */
    msp_pid_config pc = {1.0f, {1.0f, 10.0f, 0.0f, -INFINITY, INFINITY}};
    msp_controller *pid = NULL;
    CHECK(!(msp_pid_init(memory, sizeof memory, &pc, &pid) != MSP_OK), "msp_pid_init(memory, sizeof memory, &pc, &pid) != MSP_OK");
    CHECK(!(msp_mimo2_update((msp_mimo2 *)(void *)pid, r, y, u) != MSP_BAD_HANDLE || u[0] != 7.0f), "msp_mimo2_update((msp_mimo2 *)(void *)pid, r, y, u) != MSP_BAD_HANDLE || u[0] != 7.0f");
    printf("mimo2: %s\n", bad ? "FAIL" : "ok");
    return bad;
}
