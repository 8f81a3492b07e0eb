/*
 * friction-node from C, in-process: what a ros2_control controller or
 * hardware plugin does in its update(). Reads one velocity per line (m/s)
 * from stdin, steps the model once per line at the configured period, and
 * prints, per step, the model time, the feed-forward friction and the
 * minimum film thickness with 17 significant digits (exact doubles).
 *
 *   cc friction_step.c -I ../../capi/include \
 *      ../../target/release/libfriction_node_c.a -lm -lpthread -ldl -o friction_step
 *   ./friction_step [CONFIG.yaml] < velocities.txt
 *
 * Without a configuration file the built-in defaults are used.
 */
#include <stdio.h>
#include <stdlib.h>

#include "friction_node.h"

static int report(const char *what) {
    char msg[1024];
    fn_last_error(msg, sizeof msg);
    fprintf(stderr, "friction_step: %s: %s\n", what, msg);
    return 2;
}

int main(int argc, char **argv) {
    FnModel *model = NULL;
    int rc = argc > 1 ? fn_model_new_from_file(argv[1], &model)
                      : fn_model_new_from_yaml("", &model);
    if (rc != FN_OK) {
        return report("configuration");
    }
    const double dt = fn_model_dt(model);
    const double load = 20762.0; /* the shipped configuration's load, N */
    double v;
    unsigned long steps = 0, not_converged = 0;
    while (scanf("%lf", &v) == 1) {
        FnEstimate e;
        if (fn_model_step(model, v, load, dt, &e) != FN_OK) {
            fn_model_free(model);
            return report("step");
        }
        if (e.status != FN_STATUS_CONVERGED) {
            not_converged++;
        }
        printf("%.17g,%.17g,%.17g,%s\n", e.time_s, e.friction_force_n, e.h_min_m,
               fn_status_name(e.status));
        steps++;
    }
    fn_model_free(model);
    fprintf(stderr, "friction_step: %lu steps, %lu not converged\n", steps, not_converged);
    return 0;
}
