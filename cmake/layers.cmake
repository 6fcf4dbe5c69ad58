# hb_layer(name deps...): one library per folder src/<name>. Sources are globbed so that a new
# file in a layer needs no CMake edit; a layer without .cpp files is header-only (INTERFACE).
function(hb_layer name)
  file(GLOB _srcs CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${name}/*.cpp)
  if(_srcs)
    add_library(hb_${name} STATIC ${_srcs})
    target_include_directories(hb_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
    target_link_libraries(hb_${name} PUBLIC ${ARGN})
  else()
    add_library(hb_${name} INTERFACE)
    target_include_directories(hb_${name} INTERFACE ${PROJECT_SOURCE_DIR}/src)
    target_link_libraries(hb_${name} INTERFACE ${ARGN})
  endif()
endfunction()

# hb_test_dir(layer deps...): every tests/<layer>/test_*.cpp goes into one GoogleTest binary
# test_<layer>; each TEST becomes a CTest test labelled "unit" (or the label given by
# HB_TEST_LABEL in the calling directory).
function(hb_test_dir layer)
  file(GLOB _srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/test_*.cpp)
  if(NOT _srcs)
    return()
  endif()
  add_executable(test_${layer} ${_srcs})
  target_link_libraries(test_${layer} PRIVATE ${ARGN} GTest::gtest GTest::gtest_main)
  target_include_directories(test_${layer} PRIVATE ${PROJECT_SOURCE_DIR}/tests)
  if(NOT HB_TEST_LABEL)
    set(HB_TEST_LABEL unit)
  endif()
  gtest_discover_tests(test_${layer} PROPERTIES LABELS ${HB_TEST_LABEL} DISCOVERY_TIMEOUT 60)
endfunction()
