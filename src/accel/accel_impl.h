// The closed set of skipping structures and the one dispatch on them (STYLE.md habit 2):
// renderers call visit_accel(accel, f) once per frame and get the concrete type, whose cursor then
// inlines into the sample loop. The dispatch is generated from the registry's table of structures
// (src/session/structure_registry.h, kTable): one line there names a structure's concrete ray
// type, so there is no switch to extend here.
#pragma once
#include "session/structure_registry.h"
