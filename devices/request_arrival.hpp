// When a request reached this host, and waiting for an answer's due time, for t7-sim.
//
// A T7 answers a command-response request a documented time after it arrives (T-Series datasheet
// appendix A-1; t7_timing.hpp). t7-sim used to start that wait only after its own thread had woken
// for the request and parsed it, and slept it relatively, so each answer came LabJack's time plus
// two wake-ups of this host late: on an idle VM, whose halted vCPUs wake slowly, enough to push
// exchanges past bellows' [t7] response_timeout_s although no T7 would be that slow. The kernel
// stamps each received segment (SO_TIMESTAMPNS, delivered for TCP by recvmsg); the answer is due
// that arrival plus LabJack's time, never earlier.
#pragma once

namespace bellows {

/// Asks the kernel to stamp what arrives on the socket `fd` (once, after accept). False if refused.
bool enable_arrival_stamps(int fd);

/// The steady-clock time (monotonic_seconds(), the epoch of std::chrono::steady_clock) at which the
/// oldest unread data on `fd` arrived, from the kernel's stamp; `fallback_s` when there is none
/// (stamps not enabled, nothing queued). Reads nothing from the socket (it peeks). Never later
/// than now.
double request_arrival_s(int fd, double fallback_s);

/// Returns at steady-clock time `due_s` or just after, never before: sleeps to `spin_s` before it,
/// then polls the clock (a sleep overshoots by a wake-up of this host, a T7 does not).
void wait_until_s(double due_s, double spin_s);

/// The steady clock in seconds.
double steady_now_s();

}  // namespace bellows
