#pragma once
// One visitor from several lambdas, for std::visit over the XpressNet message variants
// (xpressnet_messages.hpp) in the decoder, the driver and the emulator.

namespace covtrack::lenz {

template <class... F>
struct overloaded : F... {
  using F::operator()...;
};
template <class... F>
overloaded(F...) -> overloaded<F...>;  // clang before 17 deduces no aggregate's arguments

}  // namespace covtrack::lenz
