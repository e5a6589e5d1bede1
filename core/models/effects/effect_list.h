// The effects FlexArm knows, in the order they are listed everywhere (help, candidates,
// JSON). One line per effect: its kind, its name (product API) and the function of its file
// in this folder that returns its definition (core/models/effect_registry.h). The first six
// are the seed's Section 3.2 assumptions. No include guard: included with FLEXARM_EFFECT
// defined.
FLEXARM_EFFECT(CoulombFriction, "coulomb_friction", coulombFrictionEffect)
FLEXARM_EFFECT(Backlash, "backlash", backlashEffect)
FLEXARM_EFFECT(NonlinearSpring, "nonlinear_spring", nonlinearSpringEffect)
FLEXARM_EFFECT(InputDelay, "input_delay", inputDelayEffect)
FLEXARM_EFFECT(TorqueRipple, "torque_ripple", torqueRippleEffect)
FLEXARM_EFFECT(ExtraMass, "extra_mass", extraMassEffect)
FLEXARM_EFFECT(ArmFriction, "arm_friction", armFrictionEffect)
FLEXARM_EFFECT(AsymmetricCoulomb, "asymmetric_coulomb", asymmetricCoulombEffect)
FLEXARM_EFFECT(Gravity, "gravity", gravityEffect)
FLEXARM_EFFECT(EncoderSkew, "encoder_skew", encoderSkewEffect)
