/* step.h - the step context: everything one carom_world_step knows, built
 * once by carom_world_step (world.c) and passed to every stage. The settings
 * part is fixed for the step; the solver's gather and build stages fill in
 * the solver bodies and constraints, which later stages (continuous
 * collision) read. */
#ifndef CAROM_STEP_H
#define CAROM_STEP_H

#include "carom/carom.h"
#include "impulse.h"

/* A soft contact's coefficients for one sub-step (Box2D v3's soft step):
 * bias = bias_rate * separation, lambda scaled by mass_scale, minus
 * impulse_scale times the accumulated impulse. */
typedef struct softness {
    double bias_rate, mass_scale, impulse_scale;
} softness;

softness make_softness(double hertz, double damping_ratio, double h);

struct contact_constraint;

typedef struct step_context {
    /* time */
    double dt;                   /* the step */
    int substeps;
    double h, inv_h;             /* sub-step and its inverse */
    /* contacts */
    double contact_hertz;        /* the setting, capped at a quarter of the sub-step rate */
    double contact_damping_ratio; /* the setting (solver.c stiffens loaded contacts) */
    softness soft;               /* between two moving bodies */
    softness static_soft;        /* against a static or kinematic body: twice as stiff */
    carom_position_correction correction;
    double push_max;             /* cap on the push-out speed */
    double slop;                 /* overlap every correction mode leaves alone */
    double baumgarte_rate;       /* beta / h */
    int iterations, relax_iterations;
    int warm_starting, friction, restitution, shock_propagation;
    double restitution_threshold;
    double hit_event_threshold;  /* impacts faster than this raise hit events */
    int penalty;                 /* the penalty model replaces the impulse passes */
    int penalty_implicit;
    double penalty_stiffness, penalty_damping;
    vec3 gravity;
    double gravity_length;       /* |gravity| */
    const carom_world_def *tasks; /* the world's task hooks (tasks.h) */
    /* solver bodies (the solver's gather stage): index 0 is the shared
     * immovable body */
    impulse_body *bodies;
    vec3 *dp, *dq;               /* per solver body: motion since the step began */
    const int *body_slot;        /* solver body -> store slot */
    int body_count;
    /* constraints (the solver's build stage), one per touching manifold */
    struct contact_constraint *constraints;
    int constraint_count, point_count;
    struct contact_block *blocks; /* per constraint: its normal rows as one block (contact_solver.c) */
} step_context;

/* The settings part from the world's def; no bodies or constraints yet. */
void step_context_init(step_context *ctx, const carom_world_def *def, double dt);

#endif
