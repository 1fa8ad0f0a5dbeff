/* Consumes the installed C ABI. */
#include <hemilight.h>
#include <stdio.h>

int main(void) {
  size_t count = 0;
  int major = -1;
  hemilight_version(&major, NULL, NULL);
  if (major != HEMILIGHT_VERSION_MAJOR) return 1;
  if (hemilight_hemicube_texel_count(8, &count) != HEMILIGHT_OK || count != 192) return 1;
  printf("consumer_c: ok (%u texels)\n", (unsigned)count);
  return 0;
}
