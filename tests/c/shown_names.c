/* A test harness, no controller: the C library's sn_shown (src/utils.c, included whole), the form a
 * caller's string takes in an error line. Prints each case's result on its own line between [ ]:
 * control characters, UTF-8 and a backslash; strings cut past SN_SHOWN_MAX bytes (plain, and inside a
 * 2-byte UTF-8 character); NULL; SN_SHOWN_SLOTS results used in one printf; sn_shown_n's bytes, a NUL
 * among them. */
#include <string.h>

#include "utils.c"

int main(void) {
  printf("[%s]\n", sn_shown("a\nb\tc\rd\x01" "e\x7f" "f\\n \xc3\xa9"));
  static char long_name[SN_SHOWN_MAX + 16];
  memset(long_name, 'x', SN_SHOWN_MAX - 1);
  strcpy(long_name + SN_SHOWN_MAX - 1, "\xc3\xa9z"); /* the cut falls inside the é */
  const char *cut = sn_shown(long_name);
  printf("[%zu %s]\n", strlen(cut), cut + SN_SHOWN_MAX - 4);
  memset(long_name, 'x', SN_SHOWN_MAX + 1);
  long_name[SN_SHOWN_MAX + 1] = '\0';
  cut = sn_shown(long_name);
  printf("[%zu %s]\n", strlen(cut), cut + SN_SHOWN_MAX - 3);
  strcpy(long_name, "\n");
  memset(long_name + 1, 'x', SN_SHOWN_MAX - 3);
  strcpy(long_name + SN_SHOWN_MAX - 2, "y"); /* "\n" grows by one: exactly SN_SHOWN_MAX bytes, not cut */
  cut = sn_shown(long_name);
  printf("[%zu %s]\n", strlen(cut), cut + SN_SHOWN_MAX - 3);
  printf("[%s]\n", sn_shown(NULL));
  printf("[%s %s %s %s]\n", sn_shown("1\n"), sn_shown("2\t"), sn_shown("3\r"), sn_shown("4\x1b"));
  printf("[%s]\n", sn_shown_n("a\0b\ncdef", 5));
  return 0;
}
