/* The few MPI calls of stamp-petsc, on PETSC_COMM_WORLD. MPI's handles (MPI_DOUBLE, MPI_MAX, ...)
 * are macros whose expansion differs between MPI implementations, so they are used here, in C,
 * rather than through bindgen. Each returns MPI's error code (MPI_SUCCESS = 0). */
#include <petscsys.h>
#include <time.h>

int stamp_petsc_world_rank(int *rank) { return MPI_Comm_rank(PETSC_COMM_WORLD, rank); }

int stamp_petsc_world_size(int *size) { return MPI_Comm_size(PETSC_COMM_WORLD, size); }

/* In place: op 0 = max, 1 = min, 2 = sum. */
int stamp_petsc_allreduce_u64(unsigned long long *buf, int n, int op) {
  MPI_Op o = op == 0 ? MPI_MAX : op == 1 ? MPI_MIN : MPI_SUM;
  return MPI_Allreduce(MPI_IN_PLACE, buf, n, MPI_UNSIGNED_LONG_LONG, o, PETSC_COMM_WORLD);
}

/* In place: op 0 = max, 1 = min, 2 = sum. */
int stamp_petsc_allreduce_f64(double *buf, int n, int op) {
  MPI_Op o = op == 0 ? MPI_MAX : op == 1 ? MPI_MIN : MPI_SUM;
  return MPI_Allreduce(MPI_IN_PLACE, buf, n, MPI_DOUBLE, o, PETSC_COMM_WORLD);
}

int stamp_petsc_bcast_bytes(void *buf, int n, int root) { return MPI_Bcast(buf, n, MPI_BYTE, root, PETSC_COMM_WORLD); }

int stamp_petsc_barrier(void) { return MPI_Barrier(PETSC_COMM_WORLD); }

int stamp_petsc_abort(int code) { return MPI_Abort(PETSC_COMM_WORLD, code); }

/* A barrier that gives up after `seconds` (< 0: waits for ever): *done = 1 when every rank
 * arrived, 0 on time-out (the request is then left pending: the caller aborts). */
int stamp_petsc_barrier_within(double seconds, int *done) {
  MPI_Request req;
  int flag = 0, rc = MPI_Ibarrier(PETSC_COMM_WORLD, &req);
  if (rc != MPI_SUCCESS) return rc;
  double start = MPI_Wtime();
  while (!flag) {
    rc = MPI_Test(&req, &flag, MPI_STATUS_IGNORE);
    if (rc != MPI_SUCCESS) return rc;
    if (!flag) {
      if (seconds >= 0 && MPI_Wtime() - start > seconds) break;
      struct timespec ts = {0, 1000000};
      nanosleep(&ts, NULL);
    }
  }
  *done = flag;
  return MPI_SUCCESS;
}
