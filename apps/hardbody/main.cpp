#include <cstdio>
int main() { std::puts("hardbody: not yet"); return 0; }
