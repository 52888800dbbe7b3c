// Linked with one library layer whole (tests/CMakeLists.txt): nothing to run, the link is the check.
int main() { return 0; }
