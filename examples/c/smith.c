/*
 * Tunes a Smith predictor on the device from an FOPDT model, runs it against
 * a plant simulated here in C, and prints the output every 500 samples.
 *
 * The plant is the MathWorks Smith predictor example, 5.6 e^{-93.9 s}/(40.2 s + 1),
 * sampled every 0.939 s (100 samples of dead time), the loop the Rust firmware
 * runs (firmware/src/loops.rs): set point 1, then 0.5 at half the run, an input
 * load of -0.05 from two thirds on, 10 000 samples. The same program runs on
 * the host and on a Cortex-M4F (QEMU mps2-an386); scripts/c compares its
 * output with the Rust firmware's.
 */
#include <stdio.h>
#include <math.h>

#include "msp.h"

#define SAMPLES 10000
#define CHECKS 20
#define DEAD_TIME 100 /* samples */

/* the controller's memory: a static array, nothing allocated */
static unsigned char memory[4096];

/* the plant: y[k+1] = a y[k] + K (1 - a) v[k], v the input delayed by DEAD_TIME samples */
typedef struct {
    float a, b, x;
    float line[DEAD_TIME];
    int head;
} plant;

static float plant_output(const plant *p) { return p->x; }

static void plant_advance(plant *p, float u) {
    float v = p->line[p->head];
    p->line[p->head] = u;
    p->head = (p->head + 1) % DEAD_TIME;
    p->x = p->a * p->x + p->b * v;
}

/* One controller update: out of line, so that its cost can be counted. */
__attribute__((noinline)) float c_update(msp_controller *c, float r, float y) {
    return msp_update(c, r, y);
}

int main(void) {
    const float k = 5.6f, tau = 40.2f, theta = 93.9f, ts = 0.939f;
    msp_smith_config cfg;
    msp_status s = msp_tune_smith_fopdt(k, tau, theta, ts, 0.0f, &cfg);
    if (s != MSP_OK) {
        printf("tune: %s\n", msp_status_str(s));
        return 1;
    }
    size_t need = msp_smith_size(&cfg, 0, &s);
    if (s != MSP_OK || need > sizeof memory) {
        printf("size: %s (%u bytes)\n", msp_status_str(s), (unsigned)need);
        return 1;
    }
    msp_controller *c = NULL;
    s = msp_smith_init(memory, sizeof memory, &cfg, &c);
    if (s != MSP_OK) {
        printf("init: %s\n", msp_status_str(s));
        return 1;
    }
    printf("smith: kp %.6g ti %.6g, %u bytes\n", (double)cfg.pid.kp, (double)cfg.pid.ti,
           (unsigned)need);

    plant p = {0};
    p.a = expf(-ts / tau);
    p.b = k * (1.0f - p.a);
    for (int i = 0; i < SAMPLES; i++) {
        float r = i < SAMPLES / 2 ? 1.0f : 0.5f;
        float d = i >= 2 * SAMPLES / 3 ? -0.05f : 0.0f;
        float y = plant_output(&p);
        float u = c_update(c, r, y);
        plant_advance(&p, u + d);
        if ((i + 1) % (SAMPLES / CHECKS) == 0) {
            printf("y %d %.9g\n", i + 1, (double)y);
        }
    }
    if (msp_fault(c)) {
        printf("fault\n");
        return 1;
    }
    return 0;
}
