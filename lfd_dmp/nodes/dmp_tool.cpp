// Master-free DMP command line (learn from CSV, roll out to CSV, inspect a skill library).
// See lfd_dmp/dmp_tool.hpp for the commands.
#include "lfd_dmp/dmp_tool.hpp"

#include <iostream>

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  return lfd_dmp::runDmpTool(args, std::cout, std::cerr);
}
