// The web view's threads give way to the graph: every thread the server, the event stream and the
// backend start runs at the lowest CFS weight (nice 19), so on a robot's two cores a frame that
// becomes ready preempts a PNG being drawn or a state document being written, and the viewer gets
// what the graph leaves. nice, not SCHED_IDLE: a nice-19 thread still runs a little under full
// load, so a lock it holds (the learning channel's queue, the camera tap's buffer, which the frame
// path only try-locks) is never held for unbounded time.
#pragma once

namespace orthoflow::ui {

// Lowers the calling thread's priority to nice 19 (Linux keeps a nice value per thread). Returns
// false when the system refused; the thread then keeps running at its old priority.
bool make_this_thread_background() noexcept;

// The calling thread's nice value (-20..19).
int this_thread_nice() noexcept;

}  // namespace orthoflow::ui
