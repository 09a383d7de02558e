// Android build of pdnav (for an Android workstation with the SDK and NDK installed).
// On the project's hosts the same sources are verified without Gradle: tools/android-host/run.
pluginManagement {
    repositories {
        google()
        mavenCentral()
        gradlePluginPortal()
    }
}
dependencyResolutionManagement {
    repositoriesMode.set(RepositoriesMode.FAIL_ON_PROJECT_REPOS)
    repositories {
        google()
        mavenCentral()
    }
}
rootProject.name = "pdnav"
include(":app")
