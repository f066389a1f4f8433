#pragma once
// The standard serial rates a config may name, as numbers.
namespace covtrack::serial {

bool is_supported_baud(int baud);

}  // namespace covtrack::serial
