// SIGUSR1 / SIGTERM: "checkpoint and stop". The handler only sets a flag (async-signal-safe);
// the time loop polls it and all ranks agree (an allreduce) at the next step, write a
// checkpoint and exit with code 3 ("resubmit me"). Installed after PetscInitialize, replacing
// PETSc's handler for these two signals.
#pragma once

namespace morphogen {

void install_stop_signal_handlers();
// The signal number received on this rank (0 if none).
int stop_signal_received();
const char* signal_name(int sig);

} // namespace morphogen
