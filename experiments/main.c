#include <stdio.h>
int main(void) { puts("mpmbench: under construction"); return 0; }
