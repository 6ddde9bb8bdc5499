// The MPI frame group (pipeline/run/distribute.h), built only when CMake finds MPI
// (APPARENT_HAVE_MPI): `mpirun -n N apparent render SCENE ...` or `srun apparent render ...`.
// main() starts it when a launcher started the process (Open MPI's, PMI or PMIx variables in
// the environment), so a plain `apparent` never initializes MPI.
// - `render`: every rank loads the stage (the ranks agree on it: the first failure's code and
//   message, printed by rank 0), rank r cuts and encodes frames k with k - first = r mod N, rank 0
//   writes every output in frame order (the protocol of distribute.h: MPI_Send / MPI_Recv on a
//   duplicate of MPI_COMM_WORLD, frames over 1 GiB in several messages). The .glb's frame data
//   stays with the rank that made it when rank 0 can open every rank's frame spill in the output
//   folder (shareFrameSpills): rank 0 takes the frames' descriptions and each rank copies its own
//   data into the file at the end; PLY and OBJ files are written by their ranks and renamed into
//   place by rank 0 (exporters/frame_files.h).
// - `raytrace`: the same split; rank r traces its frames and sends each picture to rank 0, which
//   writes the PNG files and the video in frame order.
// - `figure`: the same split over its pictures (the sheet's panels, row by row; or the video's
//   frames); rank 0 places them and writes the one PNG sheet or MP4.
// - Every other command runs on rank 0 alone (the other ranks return 0 at once).
// - Ranks other than 0 print nothing; rank 0 prints the progress and the summary, which says how
//   many processes shared the frames.
// Exit: every rank ends with rank 0's code (mpirun exits with it): the ranks meet in a final
// barrier and finalize MPI. When a rank does not arrive within 10 s (rank 0 left the protocol on an
// exception, after its sinks removed their temporaries and it printed its line), rank 0 calls
// MPI_Abort with its code, so that no rank is left waiting.
// MPI is initialized with MPI_THREAD_SERIALIZED: the frame loop's in-order stage calls MPI from
// whichever TBB thread runs it, one call at a time.
#pragma once

namespace apparent {

// Whether an MPI launcher started this process.
bool launchedByMpi();

// MPI_Init_thread and the group installed as frameGroup(); true when there is more than one rank.
void startMpiGroup(int* argc, char*** argv);
bool mpiRankZero();

// Ends the process's part of the job with `code` (see above) and returns the code main returns.
int finishMpiGroup(int code);

}  // namespace apparent
