// The engines a full build registers, one line each, in the registry's order after the reference.
// Each line TIPPE_ENGINE(NAME) names the function NAME_engine_info() that engines/NAME/ defines
// (with engine_entry, registry.h) and hands over through its module's entry point
// tippe_engine_NAME (TIPPE_ENGINE_ENTRY_POINT(NAME)); the registry knows the module's file from the
// name (libtippe_engine_NAME.so) and loads it on first use. registry.h and registry.cpp expand the
// list. Adding an engine: its folder engines/NAME/, tippe_add_engine(NAME ...) in
// engines/CMakeLists.txt, one line here and one row in the conformance suite
// (tests/engines/test_conformance.cpp).
// An engine's setting whose value names a file, relative to the scene file, is one line
// TIPPE_ENGINE_FILE(NAME, KEY, WHAT) (WHAT as messages name the file): the scene's resolve step
// (harness/scene/resolve.h) reads it with the scene and its bytes join the scene's content hash.
// Declared here rather than in the engine's module, so that a build without the engine reads and
// hashes a scene as the full build does.
// No include guard: expanded once per TIPPE_ENGINE or TIPPE_ENGINE_FILE definition.
#ifdef TIPPE_ENGINE
TIPPE_ENGINE(bullet)
TIPPE_ENGINE(ode)
TIPPE_ENGINE(mujoco)
TIPPE_ENGINE(dart)
TIPPE_ENGINE(simbody)
TIPPE_ENGINE(siconos)
#endif
#ifdef TIPPE_ENGINE_FILE
TIPPE_ENGINE_FILE(mujoco, model, "an MJCF file")
#endif
