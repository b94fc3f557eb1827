/* Chosen port outputs at a given rate (-output_ports, -output_ports_interval): ports.csv, for a controller or a
   co-simulation to read. Each named port body:port gives, per sample time,
     u: the wrench its load applies (the scene's -port_<name>_force ... with its profile; body frame),
     y: its collocated output, the velocity of the port point and the angular velocity (body frame),
     its inertial position, and the wrench the joints and force elements apply to it (body frame, at the port point;
     the step's multipliers, as the joint series), all SI.
   The samples are at t = k h (h: the interval), each the linear interpolation of the two monitored steps around it
   (a sample on a step is that step's row); h = 0: every step. A checkpoint keeps the sampler (the next sample, the
   last step's row), so a restarted run continues ports.csv as the run would have. */
#include <phlex_impl.h>
#include <private/transient.h>
#include <petscviewerhdf5.h>

#define PORT_COLUMNS 21 /* per port: Fx..Tz, vx..wz, x, y, z, joint_Fx..joint_Tz */

/*@C
  PhlexTransientPortsSetUp - resolves -output_ports (body:port names, n of them) against the scene's parts, before
  anything is written

  Collective
@*/
PetscErrorCode PhlexTransientPortsSetUp(MonitorContext *m, PetscInt n, char *names[], PetscReal interval)
{
  PhlexSystem sys = m->sys;

  PetscFunctionBeginUser;
  PetscCheck(n == 0 || !(interval < 0 || PetscIsInfOrNanReal(interval)), m->scene->comm, PETSC_ERR_USER_INPUT, "-output_ports_interval must be a finite time >= 0 [s] (0: every step), got %g", (double)interval);
  if (!n) PetscFunctionReturn(0);
  m->nports_out  = n;
  m->ports_every = interval;
  PetscCall(PetscMalloc3(n, &m->out_part, n, &m->out_port, n, &m->out_names));
  PetscCall(PetscMalloc2(n * PORT_COLUMNS, &m->out_prev, n * PORT_COLUMNS, &m->out_row));
  for (PetscInt i = 0; i < n; i++) {
    char      body[2 * PHLEX_NAME_LEN + 2], *colon;
    PhlexPart part = NULL;
    PetscCall(PetscStrncpy(m->out_names[i], names[i], sizeof(m->out_names[i])));
    PetscCall(PetscStrncpy(body, names[i], sizeof(body)));
    colon = strchr(body, ':');
    PetscCheck(colon && colon != body && colon[1], m->scene->comm, PETSC_ERR_USER_INPUT, "-output_ports: '%s' is not body:port (a body's name and one of its ports)", names[i]);
    *colon = 0;
    for (PetscInt p = 0; p < sys->nparts; p++) {
      PetscBool same;
      PetscCall(PetscStrcmp(sys->parts[p]->name, body, &same));
      if (same) part = sys->parts[p];
    }
    if (!part) {
      char avail[512] = "";
      for (PetscInt p = 0; p < sys->nparts; p++) {
        PetscCall(PetscStrlcat(avail, p ? ", " : "", sizeof(avail)));
        PetscCall(PetscStrlcat(avail, sys->parts[p]->name, sizeof(avail)));
      }
      SETERRQ(m->scene->comm, PETSC_ERR_USER_INPUT, "-output_ports %s: no body named '%s' (the bodies: %s)", names[i], body, avail);
    }
    PetscCall(PhlexPartFindPort(part, colon + 1, &m->out_port[i]));
    if (m->out_port[i] < 0) {
      char avail[512] = "";
      for (PetscInt p = 0; p < part->nports; p++) {
        PetscCall(PetscStrlcat(avail, p ? ", " : "", sizeof(avail)));
        PetscCall(PetscStrlcat(avail, part->ports[p].name, sizeof(avail)));
      }
      SETERRQ(m->scene->comm, PETSC_ERR_USER_INPUT, "-output_ports %s: body %s has no port '%s' (its ports: %s)", names[i], part->name, colon + 1, part->nports ? avail : "none");
    }
    m->out_part[i] = part;
    for (PetscInt l = 0; l < i; l++) PetscCheck(!(m->out_part[l] == part && m->out_port[l] == m->out_port[i]), m->scene->comm, PETSC_ERR_USER_INPUT, "-output_ports: %s is listed twice", names[i]);
  }
  m->ports_next      = 0;
  m->ports_have_prev = PETSC_FALSE;
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientPortsOpen - opens ports.csv (continued by a restart) with its header: time, then each port's columns,
  named body:port_<quantity>

  Collective
@*/
PetscErrorCode PhlexTransientPortsOpen(MonitorContext *m)
{
  const PetscInt n = m->nports_out;
  char          *header;
  size_t         len, k;

  PetscFunctionBeginUser;
  if (!n) PetscFunctionReturn(0);
  len = 8 + (size_t)n * PORT_COLUMNS * (sizeof(m->out_names[0]) + 12);
  PetscCall(PetscMalloc1(len, &header));
  PetscCall(PetscStrcpy(header, "time"));
  for (PetscInt i = 0; i < n; i++) {
    const char *q[PORT_COLUMNS] = {"Fx", "Fy", "Fz", "Tx", "Ty", "Tz", "vx", "vy", "vz", "wx", "wy", "wz", "x", "y", "z", "joint_Fx", "joint_Fy", "joint_Fz", "joint_Tx", "joint_Ty", "joint_Tz"};
    for (PetscInt c = 0; c < PORT_COLUMNS; c++) {
      PetscCall(PetscStrlen(header, &k));
      PetscCall(PetscSNPrintf(header + k, len - k, ",%s_%s", m->out_names[i], q[c]));
    }
  }
  PetscCall(PhlexOutputCSVOpen(m->scene->output, "ports.csv", header, &m->ports_csv));
  PetscCall(PetscFree(header));
  PetscFunctionReturn(0);
}

/* the chosen ports' values at the monitored state (t, X; the system evaluated there, the parts' outputs computed),
   SI, into m->out_row */
static PetscErrorCode PortsRow(MonitorContext *m, PetscReal t, Vec X)
{
  PhlexSystem       sys = m->sys;
  const PhlexUnits *u   = &m->scene->units;

  PetscFunctionBeginUser;
  for (PetscInt i = 0; i < m->nports_out; i++) {
    PhlexPart    part = m->out_part[i];
    PetscInt     port = m->out_port[i];
    PetscReal   *row  = m->out_row + i * PORT_COLUMNS, w[6] = {0, 0, 0, 0, 0, 0}, y[6], x[3], R[9], wj[6] = {0, 0, 0, 0, 0, 0};
    PhlexPartVec pv;
    if (part->ops.portinput) PetscCall((*part->ops.portinput)(part, port, t, w));
    PetscCall((*part->ops.portoutput)(part, port, y));
    PetscCall(PhlexPartGetVec(part, X, sys->q, &pv));
    PetscCall((*part->ops.portplacement)(part, port, &pv, x, R));
    PetscCall(PhlexPartRestoreVec(part, X, &pv));
    for (PetscInt k = 0; k < sys->njoints; k++) {
      PhlexJoint j = sys->joints[k];
      PetscReal  wk[6];
      if (!PhlexJointTouches(j, part)) continue;
      PetscCall(PhlexJointPortWrench(j, m->lambda + j->qoff, part, port, wk));
      for (PetscInt c = 0; c < 6; c++) wj[c] += wk[c];
    }
    for (PetscInt c = 0; c < 3; c++) {
      row[c]      = w[c] * u->force;
      row[3 + c]  = w[3 + c] * u->force * u->length;
      row[6 + c]  = y[c] * u->velocity;
      row[9 + c]  = y[3 + c] / u->time;
      row[12 + c] = x[c] * u->length;
      row[15 + c] = wj[c] * u->force;
      row[18 + c] = wj[3 + c] * u->force * u->length;
    }
  }
  PetscFunctionReturn(0);
}

static PetscErrorCode WriteSample(MonitorContext *m, PetscReal ts, const PetscReal *a, const PetscReal *b, PetscReal s)
{
  const PetscInt n = m->nports_out * PORT_COLUMNS;

  PetscFunctionBeginUser;
  PetscCall(PhlexCSVPrintf(m->ports_csv, "%.12e", (double)ts));
  for (PetscInt c = 0; c < n; c++) PetscCall(PhlexCSVPrintf(m->ports_csv, ",%.12e", (double)(b ? (1.0 - s) * a[c] + s * b[c] : a[c])));
  PetscCall(PhlexCSVPrintf(m->ports_csv, "\n"));
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientPortsStep - after a monitored step at (t, X): the samples of ports.csv up to t

  Collective
@*/
PetscErrorCode PhlexTransientPortsStep(MonitorContext *m, PetscReal t, Vec X)
{
  const PetscReal h = m->ports_every, tol = 1e-9 * m->dt_nominal; /* a sample on a step: the times summed from steps */

  PetscFunctionBeginUser;
  if (!m->nports_out) PetscFunctionReturn(0);
  PetscCall(PortsRow(m, t, X));
  if (h == 0) PetscCall(WriteSample(m, t, m->out_row, NULL, 0.0));
  else {
    for (PetscReal ts = m->ports_next * h; ts <= t + tol; ts = ++m->ports_next * h) {
      if (PetscAbsReal(ts - t) <= tol) PetscCall(WriteSample(m, ts, m->out_row, NULL, 0.0));
      else if (m->ports_have_prev && ts > m->ports_prev_t) PetscCall(WriteSample(m, ts, m->out_prev, m->out_row, (ts - m->ports_prev_t) / (t - m->ports_prev_t)));
    }
  }
  PetscCall(PetscArraycpy(m->out_prev, m->out_row, m->nports_out * PORT_COLUMNS));
  m->ports_prev_t    = t;
  m->ports_have_prev = PETSC_TRUE;
  PetscFunctionReturn(0);
}

/* what the sampler writes: the ports and the interval, as text (a restart needs the same) */
static PetscErrorCode PortsSignature(MonitorContext *m, char sig[], size_t len)
{
  PetscFunctionBeginUser;
  PetscCall(PetscSNPrintf(sig, len, "interval %.17g:", (double)m->ports_every));
  for (PetscInt i = 0; i < m->nports_out; i++) {
    PetscCall(PetscStrlcat(sig, " ", len));
    PetscCall(PetscStrlcat(sig, m->out_names[i], len));
  }
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientPortsSave - records the sampler in a checkpoint: the ports and interval, the next sample, the last
  step's time and row

  Collective
@*/
PetscErrorCode PhlexTransientPortsSave(MonitorContext *m, PetscViewer v)
{
  char      sig[4096];
  PetscReal prev;

  PetscFunctionBeginUser;
  if (!m->nports_out) PetscFunctionReturn(0);
  PetscCall(PortsSignature(m, sig, sizeof(sig)));
  PetscCall(PhlexCheckpointWriteString(v, "/ports", "signature", sig));
  PetscCall(PhlexCheckpointWriteInt(v, "/ports", "next", m->ports_next));
  prev = m->ports_have_prev ? m->ports_prev_t : -1.0;
  PetscCall(PhlexCheckpointWriteReals(v, "/ports", "previous_time", 1, &prev));
  PetscCall(PhlexCheckpointWriteReals(v, "/ports", "previous_row", m->nports_out * PORT_COLUMNS, m->out_prev));
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientPortsRestart - a restarted run's sampler from the checkpoint (ports.csv itself is continued by the
  output, PhlexOutputCSVOpen)

  Collective
@*/
PetscErrorCode PhlexTransientPortsRestart(MonitorContext *m, PetscViewer v, const char file[])
{
  char      sig[4096], ck[4096];
  PetscBool has, same;
  PetscReal prev;

  PetscFunctionBeginUser;
  if (!m->nports_out) PetscFunctionReturn(0);
  PetscCall(PetscViewerHDF5HasAttribute(v, "/ports", "signature", &has));
  PetscCheck(has, m->scene->comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) was written without -output_ports: restart with the same outputs", file);
  PetscCall(PortsSignature(m, sig, sizeof(sig)));
  PetscCall(PhlexCheckpointReadString(v, "/ports", "signature", ck, sizeof(ck)));
  PetscCall(PetscStrcmp(sig, ck, &same));
  PetscCheck(same, m->scene->comm, PETSC_ERR_USER_INPUT, "the checkpoint '%s' (option -restart) samples ports.csv at (%s), this run at (%s): restart with the same -output_ports and -output_ports_interval", file, ck, sig);
  PetscCall(PhlexCheckpointReadInt(v, "/ports", "next", &m->ports_next));
  PetscCall(PhlexCheckpointReadReals(v, "/ports", "previous_time", 1, &prev));
  PetscCall(PhlexCheckpointReadReals(v, "/ports", "previous_row", m->nports_out * PORT_COLUMNS, m->out_prev));
  m->ports_have_prev = prev >= 0 ? PETSC_TRUE : PETSC_FALSE;
  m->ports_prev_t    = prev;
  PetscFunctionReturn(0);
}

/*@C
  PhlexTransientPortsDestroy - closes ports.csv and frees the sampler

  Collective
@*/
PetscErrorCode PhlexTransientPortsDestroy(MonitorContext *m)
{
  PetscFunctionBeginUser;
  PetscCall(PetscViewerDestroy(&m->ports_csv));
  PetscCall(PetscFree3(m->out_part, m->out_port, m->out_names));
  PetscCall(PetscFree2(m->out_prev, m->out_row));
  m->nports_out = 0;
  PetscFunctionReturn(0);
}
