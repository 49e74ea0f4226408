// The engines a full build registers, one line each, in the registry's order after the reference.
// Each line TIPPE_ENGINE(NAME) names the function NAME_engine_info() that engines/NAME/ defines
// (with engine_entry, registry.h) and hands over through its module's entry point
// tippe_engine_NAME (TIPPE_ENGINE_ENTRY_POINT(NAME)); the registry knows the module's file from the
// name (libtippe_engine_NAME.so) and loads it on first use. registry.h and registry.cpp expand the
// list. Adding an engine: its folder engines/NAME/, tippe_add_engine(NAME ...) in
// engines/CMakeLists.txt, one line here and one row in the conformance suite
// (tests/engines/test_conformance.cpp).
// No include guard: expanded once per TIPPE_ENGINE definition.
TIPPE_ENGINE(bullet)
TIPPE_ENGINE(ode)
TIPPE_ENGINE(mujoco)
TIPPE_ENGINE(dart)
TIPPE_ENGINE(simbody)
TIPPE_ENGINE(siconos)
