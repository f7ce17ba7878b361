// iceoryx's C binding, for C++: its headers declare the functions without extern "C" (the library is C++
// with C linkage), so they are included here inside one. Include this instead of the binding's headers.
#pragma once

#include <time.h>
#include <cstdint>  // (pulled in by the headers below; included first, outside extern "C")
#include <ctime>

extern "C" {
#include "iceoryx_binding_c/chunk.h"
#include "iceoryx_binding_c/log.h"
#include "iceoryx_binding_c/publisher.h"
#include "iceoryx_binding_c/runtime.h"
#include "iceoryx_binding_c/service_discovery.h"
#include "iceoryx_binding_c/subscriber.h"
#include "iceoryx_binding_c/wait_set.h"
}
