/* The installed C API: its version, and a connection to no server (UNAVAILABLE, with a
 * message naming the address). Also built with `pkg-config --cflags --libs splinegrid-c`. */
#include <stdio.h>
#include <string.h>

#include "splinegrid.h"

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  sg_client* client = NULL;
  const sg_status status = sg_connect(argv[1], NULL, NULL, 5.0, &client);
  printf("c_call: version %s, %s: %s\n", sg_version(), sg_status_name(status),
         sg_last_error(client));
  const int ok = strcmp(sg_version(), argv[2]) == 0 && status == SG_UNAVAILABLE &&
                 strstr(sg_last_error(client), argv[1]) != NULL;
  sg_close(client);
  return ok ? 0 : 1;
}
