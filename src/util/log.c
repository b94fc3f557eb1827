/* Class id, log events and stages of phlex (CONVENTIONS section 6). */
#include <phlex.h>

PetscClassId  PHLEX_CLASSID;
PetscLogEvent PHLEX_BodySetUp, PHLEX_BodyAssemble, PHLEX_SysIFunction, PHLEX_SysIJacobian, PHLEX_MonitorEnergy, PHLEX_ModesSolve, PHLEX_Output, PHLEX_PortDist, PHLEX_FloatResidual, PHLEX_FloatJacobian, PHLEX_BorderedBasis, PHLEX_BorderedSetUp, PHLEX_JointResidual, PHLEX_JointJacobian, PHLEX_Assembly, PHLEX_CondensedStage, PHLEX_CondensedSetUp, PHLEX_ReducedStage, PHLEX_ReducedSetUp, PHLEX_ReducedJacobianMult, PHLEX_MatMultBlock, PHLEX_StressMaps, PHLEX_BlockCG, PHLEX_MatBlockCopy, PHLEX_PMGCoarse;
PetscLogStage PHLEX_StageSetup = -1, PHLEX_StageTransient = -1, PHLEX_StageModes = -1;

/*@C
  PhlexLogRegister - registers the phlex class id, log events and stages

  Not collective
@*/
PetscErrorCode PhlexLogRegister(void)
{
  PetscFunctionBeginUser;
  PetscCall(PetscClassIdRegister("Phlex", &PHLEX_CLASSID));
  PetscCall(PetscLogEventRegister("PhlexBodySetUp", PHLEX_CLASSID, &PHLEX_BodySetUp));
  PetscCall(PetscLogEventRegister("PhlexBodyAssem", PHLEX_CLASSID, &PHLEX_BodyAssemble));
  PetscCall(PetscLogEventRegister("PhlexSysIFunc", PHLEX_CLASSID, &PHLEX_SysIFunction));
  PetscCall(PetscLogEventRegister("PhlexCondStage", PHLEX_CLASSID, &PHLEX_CondensedStage));
  PetscCall(PetscLogEventRegister("PhlexCondSetUp", PHLEX_CLASSID, &PHLEX_CondensedSetUp));
  PetscCall(PetscLogEventRegister("PhlexRedStage", PHLEX_CLASSID, &PHLEX_ReducedStage));
  PetscCall(PetscLogEventRegister("PhlexRedSetUp", PHLEX_CLASSID, &PHLEX_ReducedSetUp));
  PetscCall(PetscLogEventRegister("PhlexRedJacMult", PHLEX_CLASSID, &PHLEX_ReducedJacobianMult));
  PetscCall(PetscLogEventRegister("PhlexMatMultBlk", PHLEX_CLASSID, &PHLEX_MatMultBlock));
  PetscCall(PetscLogEventRegister("PhlexStressMaps", PHLEX_CLASSID, &PHLEX_StressMaps));
  PetscCall(PetscLogEventRegister("PhlexSysIJac", PHLEX_CLASSID, &PHLEX_SysIJacobian));
  PetscCall(PetscLogEventRegister("PhlexMonEnergy", PHLEX_CLASSID, &PHLEX_MonitorEnergy));
  PetscCall(PetscLogEventRegister("PhlexModesSolve", PHLEX_CLASSID, &PHLEX_ModesSolve));
  PetscCall(PetscLogEventRegister("PhlexOutput", PHLEX_CLASSID, &PHLEX_Output));
  PetscCall(PetscLogEventRegister("PhlexPortDist", PHLEX_CLASSID, &PHLEX_PortDist));
  PetscCall(PetscLogEventRegister("PhlexFloatResid", PHLEX_CLASSID, &PHLEX_FloatResidual));
  PetscCall(PetscLogEventRegister("PhlexFloatJac", PHLEX_CLASSID, &PHLEX_FloatJacobian));
  PetscCall(PetscLogEventRegister("PhlexBordBasis", PHLEX_CLASSID, &PHLEX_BorderedBasis));
  PetscCall(PetscLogEventRegister("PhlexBordSetUp", PHLEX_CLASSID, &PHLEX_BorderedSetUp));
  PetscCall(PetscLogEventRegister("PhlexBlockCG", PHLEX_CLASSID, &PHLEX_BlockCG));
  PetscCall(PetscLogEventRegister("PhlexPMGCoarse", PHLEX_CLASSID, &PHLEX_PMGCoarse));
  PetscCall(PetscLogEventRegister("PhlexMatBlkCopy", PHLEX_CLASSID, &PHLEX_MatBlockCopy));
  PetscCall(PetscLogEventRegister("PhlexJointResid", PHLEX_CLASSID, &PHLEX_JointResidual));
  PetscCall(PetscLogEventRegister("PhlexJointJac", PHLEX_CLASSID, &PHLEX_JointJacobian));
  PetscCall(PetscLogEventRegister("PhlexAssembly", PHLEX_CLASSID, &PHLEX_Assembly));
  PetscFunctionReturn(0);
}

/*@C
  PhlexLogStagePush - pushes a log stage, registering it on first use (-log_view then lists only the stages the
  run went through: PETSc 3.18 prints a registered but unused stage as "Unknown")

  Not collective
@*/
PetscErrorCode PhlexLogStagePush(const char name[], PetscLogStage *stage)
{
  PetscFunctionBeginUser;
  if (*stage < 0) {
    /* PETSc 3.18 registers a stage "PCMPI" for its MPI linear-solver server (with the KSP package, i.e. before the
       first phlex stage), which phlex never uses: -log_view would list it as an empty "Unknown" stage */
    PetscLogStage pcmpi = -1;
    PetscCall(PetscLogStageGetId("PCMPI", &pcmpi));
    if (pcmpi > 0) PetscCall(PetscLogStageSetVisible(pcmpi, PETSC_FALSE));
    PetscCall(PetscLogStageRegister(name, stage));
  }
  PetscCall(PetscLogStagePush(*stage));
  PetscFunctionReturn(0);
}
