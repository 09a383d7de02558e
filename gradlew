#!/usr/bin/env sh
# Runs the Gradle wrapper (gradle/wrapper/gradle-wrapper.properties pins Gradle 8.11.1).
# The wrapper jar is not checked in (a binary); create it once with an installed Gradle:
#   gradle wrapper --gradle-version 8.11.1
# (docs/android.md, "On an Android workstation"). This script then finds and runs it.
APP_HOME=$(cd "$(dirname "$0")" && pwd -P) || exit 1
JAR="$APP_HOME/gradle/wrapper/gradle-wrapper.jar"
if [ ! -f "$JAR" ]; then
  echo "gradlew: $JAR missing: run 'gradle wrapper --gradle-version 8.11.1' once (docs/android.md)" >&2
  exit 1
fi
if [ -n "$JAVA_HOME" ]; then JAVA="$JAVA_HOME/bin/java"; else JAVA=java; fi
command -v "$JAVA" >/dev/null 2>&1 || { echo "gradlew: no java (set JAVA_HOME)" >&2; exit 1; }
exec "$JAVA" $JAVA_OPTS $GRADLE_OPTS "-Dorg.gradle.appname=gradlew" -classpath "$JAR" \
  org.gradle.wrapper.GradleWrapperMain "$@"
