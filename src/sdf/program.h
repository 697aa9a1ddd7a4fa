/* fovea — the compiled program of a signed distance field: the opcodes and the instruction that
 * sdf/compile.c emits and the evaluators (sdf/kernel.h) run. It is the SDF module's interface to
 * kernel code: the flat scene (kernel/kscene.h) carries every SDF object's program as an array of
 * these instructions, so the device evaluates exactly what the CPU does. sdf_impl.h keeps the rest
 * of a compiled field (its bounds and constants), private to the module.
 */
#ifndef FV_SDF_PROGRAM_H
#define FV_SDF_PROGRAM_H

typedef enum fv_sdf_opcode {
    FV_OP_SPHERE,      /* f0 r */
    FV_OP_BOX,         /* f0..2 half extents */
    FV_OP_ROUND_BOX,   /* f0..2 inner half extents (b - r), f3 r */
    FV_OP_TORUS,       /* f0 R, f1 r */
    FV_OP_CAPSULE,     /* f0..2 a, f3..5 b - a, f6 1/|b - a|^2 (0 when a = b), f7 r */
    FV_OP_CYLINDER,    /* f0 r, f1 h */
    FV_OP_CONE,        /* f0 r1, f1 r2, f2 h, f3 r2 - r1, f4 2h, f5 1/((r2-r1)^2 + 4h^2) */
    FV_OP_PLANE,       /* f0..2 n, f3 h */
    FV_OP_HEIGHTFIELD, /* f0 base, f1 amplitude, f2 frequency, f3 1/Lipschitz, ia octaves, ib seed */
    FV_OP_UNION,
    FV_OP_SUBTRACT,
    FV_OP_INTERSECT,
    FV_OP_SMOOTH_UNION, /* f0 k, f1 1/k */
    FV_OP_XFORM_PUSH,   /* f0..8 R^T row-major, f9..11 t, f12 1/s */
    FV_OP_XFORM_POP,    /* f0 s */
    FV_OP_REPEAT_PUSH,  /* f0..2 period (0: none), f3..5 1/period, f6..8 cell limit n (0: none) */
    FV_OP_REPEAT_POP,   /* f0 margin m between the child's bounds and its cell, f1..3 / f4..6 the box
                           holding every copy (+-1e30 where unlimited) */
    FV_OP_CULL_BEGIN,   /* ia groups, ib data ops that follow (skipped), f0 the chain's magnitude */
    FV_OP_CULL_DATA,    /* a box: f0..2 lo, f3..5 hi (+-1e30 where unbounded), f6 c (d >= c dist(p, box)
                           outside it), material 1 when the field never exceeds the distance to the
                           box's farthest point; a group's also ia its first member's data op, ib count */
    FV_OP_CULL,         /* ia the op to jump to when culled, ib the index of its CULL_DATA op */
    FV_OP_CULL_END      /* pops what CULL_BEGIN pushed, leaving the union's value */
} fv_sdf_opcode;

typedef struct fv_sdf_op {
    int code;     /* fv_sdf_opcode */
    int material; /* leaves */
    int ia, ib;   /* integer parameters */
    float f[13];
} fv_sdf_op;

#endif
