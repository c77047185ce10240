// Thread placement on the real machine: pin the calling thread to hardware threads
// (PUs, by OS index), read the binding back, current CPU, thread names.
// Every function acts on the calling thread only; any thread may call them.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace spindle {

// Binds the calling thread to one PU (OS index). Throws spindle::Error naming the PU
// when it does not exist on this machine or the OS refuses.
void pin_current_thread(unsigned os_pu);
// Binds the calling thread to a set of PUs (OS indices); same errors.
void pin_current_thread(std::span<const unsigned> os_pus);
// Lets the calling thread run on every PU the process may use.
void unpin_current_thread();
// The OS indices of the PUs the calling thread is bound to, ascending.
std::vector<unsigned> current_binding();
// The OS index of the PU the calling thread last ran on (-1 if unknown).
int current_cpu() noexcept;

// Names the calling thread (truncated to 15 characters, the Linux limit).
void set_current_thread_name(std::string_view name);
std::string current_thread_name();

}  // namespace spindle
